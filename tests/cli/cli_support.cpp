#include "cli_support.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>

namespace tega::test {

CommandResult run_tega(const std::string& arguments) { return run_command(std::string(TEGA_EXECUTABLE) + " " + arguments); }

CommandResult run_command(const std::string& command_line) {
  const std::string command = "(" + command_line + ") 2>&1";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  while (size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace tega::test
