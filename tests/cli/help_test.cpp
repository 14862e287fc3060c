#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
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

TEST(Cli, UnknownCommandIsAnErrorEvenWhenAskedForHelp) {
  for (const char* arguments : {"nosuch --help", "nosuch", "-v nosuch --help"}) {
    const auto r = run_tega(arguments);
    EXPECT_NE(r.exit_code, 0) << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find("unknown command 'nosuch'"), std::string::npos) << arguments << "\n" << r.output;
  }
}

TEST(Cli, UnknownFlagIsAnError) {
  const auto r = run_tega("dataset check --data x --no-such-flag");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no-such-flag"), std::string::npos) << r.output;
}

TEST(Cli, EveryCommandDescribesEveryFlag) {
  for (const char* command : {"dataset check", "dataset build", "synth", "rig convert", "ingest multiface", "train",
                              "eval", "render", "export", "run", "status", "capture", "capture list", "capture check",
                              "capture session", "capture validate", "calibrate", "calibrate board", "mvs",
                              "mvs photos", "mvs mesh-workspace", "track", "landmarks train", "inspect"}) {
    const auto r = run_tega(std::string(command) + " --help");
    if (r.output.find("unknown command") != std::string::npos ||
        r.output.find("could not be matched") != std::string::npos)
      continue;  // command not built here
    EXPECT_EQ(r.exit_code, 0) << command << "\n" << r.output;
    // CLI11 prints each option on its own line: the flag, its type in capitals
    // (TEXT, INT:POSITIVE=1, REQUIRED ...), then its description. A flag
    // without a description has no lowercase word after it.
    std::istringstream lines(r.output);
    for (std::string line; std::getline(lines, line);) {
      std::istringstream tokens(line);
      std::string flag, token;
      tokens >> flag;
      if (flag.rfind("--", 0) != 0) continue;
      int words = 0;
      while (tokens >> token) {
        words += std::all_of(token.begin(), token.end(), [](char c) { return std::islower(c) || std::ispunct(c); }) &&
                 std::count_if(token.begin(), token.end(), [](char c) { return std::islower(c); }) >= 2;
      }
      EXPECT_GE(words, 1) << command << ": undocumented flag: " << line;
    }
  }
}

}  // namespace
