#pragma once
// Runs the real `tega` executable, as a user would.

#include <string>

namespace tega::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// `command` run by the shell.
CommandResult run_command(const std::string& command);
// `arguments` is appended to the tega executable's path and run by the shell.
CommandResult run_tega(const std::string& arguments);

}  // namespace tega::test
