#pragma once
// Which subcommands this `tega` binary has: stages whose command is missing
// are reported as unavailable instead of failing one shard at a time.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace tega::cli {

inline bool has_subcommand(const CLI::App& root, const std::vector<std::string>& path) {
  const CLI::App* app = &root;
  for (const auto& name : path) {
    const auto found = app->get_subcommands([&](const CLI::App* sub) { return sub->get_name() == name; });
    if (found.empty()) return false;
    app = found.front();
  }
  return true;
}

}  // namespace tega::cli
