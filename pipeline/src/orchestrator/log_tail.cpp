#include "tega/pipeline/log_tail.h"

#include <fstream>
#include <sstream>
#include <vector>

namespace tega::pipeline {
namespace {

constexpr std::streamoff kTailBytes = 16384;

std::vector<std::string> tail_lines(const std::filesystem::path& log) {
  std::ifstream in(log, std::ios::binary | std::ios::ate);
  if (!in) return {};
  const std::streamoff size = in.tellg();
  in.seekg(std::max<std::streamoff>(0, size - kTailBytes));
  std::stringstream text;
  text << in.rdbuf();
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

}  // namespace

std::string last_line(const std::filesystem::path& log) {
  const auto lines = tail_lines(log);
  return lines.empty() ? "" : lines.back();
}

std::string last_error_line(const std::filesystem::path& log) {
  const auto lines = tail_lines(log);
  for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
    if (it->find("error") != std::string::npos) return *it;
  }
  return lines.empty() ? "(the log is empty)" : lines.back();
}

}  // namespace tega::pipeline
