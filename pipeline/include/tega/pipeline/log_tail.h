#pragma once
// The end of a shard's log, for error messages and progress lines.

#include <filesystem>
#include <string>

namespace tega::pipeline {

std::string last_line(const std::filesystem::path& log);  // last non-empty line, "" if none
// The last line that reports an error ("tega: error: ..."), else the last line.
std::string last_error_line(const std::filesystem::path& log);

}  // namespace tega::pipeline
