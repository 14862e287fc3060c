#pragma once
// Line-oriented reading and writing of numbers, shared by the COLMAP and KRT
// formats: every parse error names the file and the line.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tega::rig_text {

// The shortest decimal text that reads back to exactly `value`.
std::string format_number(double value);
// Numbers separated by single spaces.
std::string format_numbers(const std::vector<double>& values);

std::vector<std::string_view> split_words(std::string_view line);

class LineReader {
 public:
  explicit LineReader(std::filesystem::path file);  // throws tega::Error

  // The next line without its line break, or nullopt at the end of the file.
  std::optional<std::string> next();
  // Throws tega::Error "<file>: line <n>: <what>" for the line next() read
  // last (one past the last line once the file has ended).
  [[noreturn]] void fail(const std::string& what) const;

  double number(std::string_view word, const std::string& what) const;
  long integer(std::string_view word, const std::string& what) const;
  // `line` as exactly `count` numbers; errors read "expected <what> (<count>
  // numbers), found ...".
  std::vector<double> numbers(std::string_view line, size_t count, const std::string& what) const;

 private:
  std::filesystem::path file_;
  std::string text_;
  size_t position_ = 0;
  int line_number_ = 0;
};

}  // namespace tega::rig_text
