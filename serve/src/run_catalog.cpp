#include "tega/serve/run_catalog.h"

#include <algorithm>

#include "tega/core/error.h"

namespace tega::serve {

namespace fs = std::filesystem;

namespace {

constexpr const char* kRunFiles[] = {"options.yaml", "checkpoint.safetensors", "run.json"};

bool looks_like_run(const fs::path& directory) {
  return fs::exists(directory / "options.yaml") || fs::exists(directory / "checkpoint.safetensors");
}

void check_run(const fs::path& run) {
  for (const char* name : kRunFiles)
    if (!fs::is_regular_file(run / name))
      throw Error(run / name, "is missing: not a finished training run (tega train --out RUN writes it)");
}

}  // namespace

std::vector<RunLocation> find_runs(const fs::path& run_or_workspace) {
  if (!fs::is_directory(run_or_workspace))
    throw Error(run_or_workspace, "is not a directory: give a training run or a tega run workspace");
  const fs::path target = fs::canonical(run_or_workspace);
  if (looks_like_run(target)) {
    check_run(target);
    return {{target.filename().string(), target, target / "eval.json"}};
  }
  const fs::path train = target / "train";
  std::vector<RunLocation> runs;
  if (fs::is_directory(train))
    for (const auto& entry : fs::directory_iterator(train)) {
      const std::string subject = entry.path().filename().string();
      // Leading dots: a shard being made or replaced (docs/pipeline.md#workspace).
      if (!entry.is_directory() || subject.starts_with(".") || !fs::is_directory(entry.path() / "run")) continue;
      const fs::path run = fs::canonical(entry.path() / "run");
      check_run(run);
      runs.push_back({subject, run, target / "eval" / subject / "eval.json"});
    }
  if (runs.empty())
    throw Error(run_or_workspace,
                "holds no training run: neither a run (options.yaml, checkpoint.safetensors, run.json) nor a "
                "workspace with train/<subject>/run");
  std::sort(runs.begin(), runs.end(), [](const RunLocation& a, const RunLocation& b) { return a.id < b.id; });
  return runs;
}

}  // namespace tega::serve
