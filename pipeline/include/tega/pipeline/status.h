#pragma once
// `tega status`: the state of every shard of a workspace, as text or JSON.
// States: done, stale (committed, but options, inputs or the tool changed, or
// an output file is missing), pending (never committed), running, failed
// (with the error and the log), interrupted (its run was killed or stopped),
// blocked (an input cannot be computed, e.g. a capture that does not exist),
// unavailable (its stage is not implemented or not in this build).

#include <filesystem>
#include <string>
#include <vector>

#include "tega/pipeline/stage_graph.h"

namespace tega::pipeline {

struct ShardStatus {
  std::string shard;
  std::string state;
  std::string reason;    // why it is not done; the error of a failed shard
  std::string log;       // its log file, once it has run
  std::string finished;  // when the committed shard finished
  double seconds = 0;    // how long its command took
  // A done shard that provides a dataset: the images and frames its producer
  // left out (dataset_gap_summary); empty when there are none.
  std::string dataset_gaps;
  // A running shard of a Slurm run: "slurm job 1234 PENDING" (as of the run's last squeue poll).
  std::string cluster_job;
};

struct StageStatus {
  std::string name, kind;
  bool available = true;
  std::string unavailable_reason;
  std::vector<ShardStatus> shards;
};

struct WorkspaceStatus {
  std::filesystem::path workspace, config;
  bool run_in_progress = false;
  std::vector<StageStatus> stages;
};

WorkspaceStatus workspace_status(const StageGraph& graph, const std::string& tool_version);
std::string status_text(const WorkspaceStatus& status);
std::string status_json(const WorkspaceStatus& status);

}  // namespace tega::pipeline
