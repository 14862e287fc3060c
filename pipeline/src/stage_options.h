#pragma once
// How a stage command resolves its options: the defaults, then the --config
// file's section, then each --set key=value, then the command's own flags;
// and how --print-options shows them (the section, then every option with its
// documentation). StageOptionFlags adds those three flags to a command.

#include <CLI/CLI.hpp>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "tega/core/error.h"
#include "tega/core/options.h"

namespace tega::cli {

// Each --set key=value, in order.
template <class Options>
void apply_overrides(Options& options, const std::vector<std::string>& overrides) {
  for (const auto& kv : overrides) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) throw Error("--set " + kv + ": expected key=value");
    set_option(options, kv.substr(0, eq), kv.substr(eq + 1));
  }
}

// The options as YAML, under `section` (as a workspace config holds them), or
// alone where `section` is empty (as a file of one stage's options holds them).
template <class Options>
void print_stage_options(const std::string& section, const Options& options) {
  if (section.empty()) {
    std::cout << options_to_yaml(options);
    return;
  }
  std::cout << section << ":\n";
  std::istringstream yaml(options_to_yaml(options));
  for (std::string line; std::getline(yaml, line);) std::cout << "  " << line << "\n";
}

// A stage command's --config, --set and --print-options. Lives as long as
// the command (CLI11 writes into it).
struct StageOptionFlags {
  std::string config;
  std::vector<std::string> overrides;
  bool print = false;
  std::string section;  // of the config file, and what --print-options prints under; "": the whole file

  // `section` as above; `what` names the options in help ("track", "training");
  // `set_example`: a key=value that --set's help shows.
  void add_to(CLI::App& command, const std::string& section, const std::string& what, const std::string& set_example);

  // The defaults, then the config file, then each --set.
  template <class Options>
  Options load() const {
    Options options;
    if (!config.empty()) load_options(options, config, section);
    apply_overrides(options, overrides);
    return options;
  }

  // Prints the options and returns true when --print-options was given.
  template <class Options>
  bool print_if_asked(const Options& options) const {
    if (print) print_stage_options(section, options);
    return print;
  }
};

}  // namespace tega::cli
