#pragma once
// `tega run`: runs a stage graph's shards on an executor, skipping those whose
// manifest matches, committing each finished shard atomically, and carrying on
// past failures with every shard that does not depend on them
// (docs/pipeline.md).

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "tega/pipeline/executor.h"
#include "tega/pipeline/stage_graph.h"

namespace tega::pipeline {

struct RunRequest {
  std::vector<std::string> only;   // run just these stages; what they depend on must be done
  std::vector<std::string> from;   // re-run these stages and everything downstream
  std::vector<std::string> force;  // re-run these stages even where they are done
  std::filesystem::path tega_executable;  // what shard commands run
  std::string tool_version;               // part of every fingerprint
  std::chrono::seconds heartbeat{30};     // how often to report on long-running shards
};

struct RunSummary {
  int up_to_date = 0, ran = 0, failed = 0, blocked = 0, unavailable = 0;
  bool interrupted = false;
  std::vector<std::string> problems;  // a line per failed, blocked or unavailable shard

  int exit_code() const { return interrupted ? 130 : (failed + blocked + unavailable) ? 1 : 0; }
};

// Holds the workspace's lock for the whole run (throws tega::Error when
// another run holds it). Returns once every selected shard is done, failed or
// blocked, or soon after `stop_requested` becomes true (running jobs are then
// cancelled and their staging directories left for the next run to remove).
RunSummary run_pipeline(const StageGraph& graph, const RunRequest& request, Executor& executor,
                        const std::atomic<bool>& stop_requested);

// The config a workspace was last run with, with its workspace set to `root`.
PipelineConfig recorded_config(const std::filesystem::path& root);

}  // namespace tega::pipeline
