#pragma once
// Errors that reach the user. Every message names the file (or other input)
// at fault and what is wrong with it, so that the CLI can print it verbatim.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace tega {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  // "<path>: <message>"
  Error(const std::filesystem::path& file, const std::string& message)
      : std::runtime_error(file.string() + ": " + message) {}
};

}  // namespace tega
