#pragma once
// The runs `tega serve` was given: one run directory, or every committed
// train/<subject>/run of a `tega run` workspace.

#include <filesystem>
#include <string>
#include <vector>

namespace tega::serve {

struct RunLocation {
  std::string id;                   // names the run in URLs: the subject, or the run directory's name
  std::filesystem::path run;        // canonical
  std::filesystem::path eval_json;  // where its eval.json would be (it may not exist)
};

// Throws tega::Error naming the path when it is neither a run (options.yaml,
// checkpoint.safetensors and run.json) nor a workspace with at least one;
// a workspace's run that lacks one of them is an error naming that file.
std::vector<RunLocation> find_runs(const std::filesystem::path& run_or_workspace);

}  // namespace tega::serve
