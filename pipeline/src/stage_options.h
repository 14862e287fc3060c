#pragma once
// How a stage command resolves its options: the defaults, then the --config
// file's section, then each --set key=value; and how --print-options shows
// them (the section, then every option with its documentation).

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

template <class Options>
Options load_stage_options(const std::string& config, const std::string& section,
                           const std::vector<std::string>& overrides) {
  Options options;
  if (!config.empty()) load_options(options, config, section);
  apply_overrides(options, overrides);
  return options;
}

template <class Options>
void print_stage_options(const std::string& section, const Options& options) {
  std::cout << section << ":\n";
  std::istringstream yaml(options_to_yaml(options));
  for (std::string line; std::getline(yaml, line);) std::cout << "  " << line << "\n";
}

}  // namespace tega::cli
