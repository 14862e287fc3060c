#include "rig_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::rig_text {

std::string format_number(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string format_numbers(const std::vector<double>& values) {
  std::string out;
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ' ';
    out += format_number(values[i]);
  }
  return out;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  constexpr std::string_view kSpace = " \t\r\v\f";
  size_t begin = line.find_first_not_of(kSpace);
  while (begin != std::string_view::npos) {
    const size_t end = std::min(line.find_first_of(kSpace, begin), line.size());
    words.push_back(line.substr(begin, end - begin));
    begin = line.find_first_not_of(kSpace, end);
  }
  return words;
}

LineReader::LineReader(std::filesystem::path file)
    : file_(std::move(file)), text_(read_text_file(file_)) {}

std::optional<std::string> LineReader::next() {
  ++line_number_;
  if (position_ >= text_.size()) return std::nullopt;
  size_t end = text_.find('\n', position_);
  if (end == std::string::npos) end = text_.size();
  std::string line = text_.substr(position_, end - position_);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  position_ = end + 1;
  return line;
}

void LineReader::fail(const std::string& what) const {
  throw Error(file_, "line " + std::to_string(line_number_) + ": " + what);
}

double LineReader::number(std::string_view word, const std::string& what) const {
  double value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size() || !std::isfinite(value))
    fail("expected " + what + ", found '" + std::string(word) + "'");
  return value;
}

long LineReader::integer(std::string_view word, const std::string& what) const {
  long value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size())
    fail("expected " + what + ", found '" + std::string(word) + "'");
  return value;
}

std::vector<double> LineReader::numbers(std::string_view line, size_t count,
                                        const std::string& what) const {
  const std::string expected = what + " (" + std::to_string(count) + " numbers)";
  const std::vector<std::string_view> words = split_words(line);
  if (words.size() != count)
    fail("expected " + expected + ", found " + std::to_string(words.size()) + " value" +
         (words.size() == 1 ? "" : "s"));
  std::vector<double> values;
  values.reserve(count);
  for (std::string_view word : words) values.push_back(number(word, expected));
  return values;
}

}  // namespace tega::rig_text
