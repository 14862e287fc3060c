#include <gtest/gtest.h>

#include <sstream>

#include "cli_support.h"

namespace {

using tega::test::run_tega;

TEST(Cli, HelpListsTheCommands) {
  const auto r = run_tega("--help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("dataset"), std::string::npos) << r.output;
}

TEST(Cli, NoCommandIsAnError) {
  const auto r = run_tega("");
  EXPECT_NE(r.exit_code, 0);
}

TEST(Cli, UnknownFlagIsAnError) {
  const auto r = run_tega("dataset check --data x --no-such-flag");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no-such-flag"), std::string::npos) << r.output;
}

TEST(Cli, EveryCommandDescribesEveryFlag) {
  for (const char* command : {"dataset check", "synth", "rig convert"}) {
    const auto r = run_tega(std::string(command) + " --help");
    if (r.output.find("could not be matched") != std::string::npos) continue;  // command not built here
    EXPECT_EQ(r.exit_code, 0) << command << "\n" << r.output;
    // CLI11 prints each option on its own line followed by its description;
    // an option line without text after the flag and type means an undocumented flag.
    std::istringstream lines(r.output);
    for (std::string line; std::getline(lines, line);) {
      const auto dash = line.find_first_not_of(' ');
      if (dash == std::string::npos || line.compare(dash, 2, "--") != 0) continue;
      const auto gap = line.find("  ", dash);
      ASSERT_NE(gap, std::string::npos) << command << ": undocumented flag: " << line;
      EXPECT_NE(line.find_first_not_of(' ', gap), std::string::npos) << command << ": " << line;
    }
  }
}

}  // namespace
