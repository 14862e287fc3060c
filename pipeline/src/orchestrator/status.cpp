#include "tega/pipeline/status.h"

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "tega/core/dataset.h"
#include "tega/core/dataset_gaps.h"
#include "tega/core/error.h"
#include "tega/core/progress.h"
#include "tega/pipeline/manifest.h"
#include "tega/pipeline/slurm_batch.h"
#include "tega/pipeline/workspace.h"

namespace tega::pipeline {
namespace fs = std::filesystem;

namespace {

// What changed between a manifest's fingerprint and the current one.
std::string change_between(const Fingerprint& then, const Fingerprint& now) {
  if (then.tool_version != now.tool_version) return "the tool changed (" + then.tool_version + " -> " + now.tool_version + ")";
  if (then.options_yaml != now.options_yaml) return "its options changed";
  std::map<std::string, std::string> before(then.inputs.begin(), then.inputs.end());
  for (const auto& [name, hash] : now.inputs) {
    const auto it = before.find(name);
    if (it == before.end()) return "it has a new input: " + name;
    if (it->second != hash) return "its input " + name + " changed";
  }
  return "its inputs changed";
}

// What a committed dataset lacks. One that cannot be read has no report here:
// the stage that reads it (dataset check, train) names what is wrong.
std::string dataset_gaps(const fs::path& dataset) {
  try {
    return dataset_gap_summary(read_dataset(dataset));
  } catch (const Error&) {
    return "";
  }
}

// "slurm job 1234 RUNNING" from the record a Slurm run keeps beside the log. A record older than
// the shard's state record was left by an earlier run that was killed, not written for this one.
std::string cluster_job(const fs::path& record_file, const fs::path& state_file) {
  std::error_code record_error, state_error;
  const auto record_time = fs::last_write_time(record_file, record_error);
  const auto state_time = fs::last_write_time(state_file, state_error);
  if (record_error || state_error || record_time < state_time) return "";
  const auto job = read_slurm_job_record(record_file);
  return job ? "slurm job " + job->job_id + " " + job->state : "";
}

ShardStatus shard_status(const StageGraph& graph, size_t stage_index, size_t subject_index, const Workspace& ws,
                         bool active, const std::string& tool_version,
                         const std::map<std::pair<size_t, size_t>, ShardStatus>& earlier,
                         std::map<std::pair<size_t, size_t>, std::string>& output_hashes) {
  const Stage& stage = graph.stages()[stage_index];
  const std::string& subject = graph.config().subjects[subject_index].name;
  ShardStatus st;
  st.shard = subject;
  if (!stage.available) {
    st.state = "unavailable";
    st.reason = stage.unavailable_reason;
    return st;
  }
  std::optional<Manifest> manifest;
  try {
    manifest = read_manifest(ws.manifest_file(stage.name(), subject));
  } catch (const Error& e) {
    st.state = "stale";
    st.reason = e.what();
    return st;
  }
  if (manifest) {
    st.finished = manifest->finished;
    st.seconds = manifest->seconds;
    st.log = manifest->log;
  }
  const auto state = read_shard_state(ws.state_file(stage.name(), subject));
  if (state && state->state == "running" && active) {
    st.state = "running";
    st.log = state->log;
    st.cluster_job = cluster_job(slurm_job_files(state->log).record, ws.state_file(stage.name(), subject));
    return st;
  }
  if (state && state->state == "failed") {
    st.state = "failed";
    st.reason = state->error;
    st.log = state->log;
    return st;
  }
  for (size_t in : stage.inputs) {
    const ShardStatus& input = earlier.at({in, subject_index});
    if (input.state == "done") continue;
    st.state = manifest ? "stale" : "pending";
    st.reason = "its input " + graph.stages()[in].name() + "/" + subject + " is " + input.state;
    return st;
  }
  Fingerprint now;
  try {
    now = fingerprint_shard(graph, stage_index, subject_index, tool_version,
                            [&](size_t in, size_t j) { return output_hashes.at({in, j}); });
  } catch (const Error& e) {
    st.state = "blocked";
    st.reason = e.what();
    return st;
  }
  if (!manifest) {
    const bool interrupted = state && (state->state == "interrupted" || state->state == "running");
    st.state = interrupted ? "interrupted" : "pending";
    st.reason = interrupted ? "its run stopped before it finished" : "not run yet";
    if (state) st.log = state->log;
    return st;
  }
  if (manifest->key != now.key()) {
    st.state = "stale";
    st.reason = change_between(manifest->fingerprint, now);
    return st;
  }
  if (const auto damage = damaged_output(ws.shard_dir(stage.name(), subject), *manifest); !damage.empty()) {
    st.state = "stale";
    st.reason = "output " + damage;
    return st;
  }
  st.state = "done";
  output_hashes[{stage_index, subject_index}] = manifest->output_hash;
  if (const auto dataset = stage.kind->provides.find("dataset"); dataset != stage.kind->provides.end())
    st.dataset_gaps = dataset_gaps(ws.shard_dir(stage.name(), subject) / dataset->second);
  return st;
}

}  // namespace

WorkspaceStatus workspace_status(const StageGraph& graph, const std::string& tool_version) {
  const PipelineConfig& config = graph.config();
  const Workspace ws(config.workspace);
  WorkspaceStatus status;
  status.workspace = config.workspace;
  status.config = config.source;
  status.run_in_progress = run_in_progress(config.workspace);
  std::map<std::pair<size_t, size_t>, ShardStatus> earlier;
  std::map<std::pair<size_t, size_t>, std::string> output_hashes;
  for (size_t s = 0; s < graph.stages().size(); ++s) {
    const Stage& stage = graph.stages()[s];
    StageStatus stage_status{stage.name(), stage.kind->name, stage.available, stage.unavailable_reason, {}};
    for (size_t j = 0; j < config.subjects.size(); ++j) {
      ShardStatus st = shard_status(graph, s, j, ws, status.run_in_progress, tool_version, earlier, output_hashes);
      earlier[{s, j}] = st;
      stage_status.shards.push_back(std::move(st));
    }
    status.stages.push_back(std::move(stage_status));
  }
  return status;
}

std::string status_text(const WorkspaceStatus& status) {
  std::ostringstream out;
  out << "workspace " << status.workspace.string() << " (config " << status.config.string() << "; "
      << (status.run_in_progress ? "a run is in progress" : "no run in progress") << ")\n";
  std::map<std::string, int> totals;
  for (const auto& stage : status.stages) {
    std::map<std::string, int> counts;
    for (const auto& shard : stage.shards) ++counts[shard.state];
    out << stage.name << " (" << stage.kind << "):";
    for (const auto& [state, n] : counts) {
      out << " " << n << " " << state;
      totals[state] += n;
    }
    if (!stage.available) out << " -- " << stage.unavailable_reason;
    out << "\n";
    for (const auto& shard : stage.shards) {
      out << "  " << shard.shard << "  " << shard.state;
      if (shard.state == "done") out << "  " << shard.finished << "  " << Progress::format_duration(shard.seconds);
      if (!shard.reason.empty() && stage.available) out << "  " << shard.reason;
      if (!shard.cluster_job.empty()) out << "  " << shard.cluster_job;
      if (shard.state == "interrupted" || shard.state == "running") {
        out << "  log: " << shard.log;
      }
      if (!shard.dataset_gaps.empty()) out << "  dataset gaps: " << shard.dataset_gaps;
      out << "\n";
    }
  }
  out << "total:";
  for (const auto& [state, n] : totals) out << " " << n << " " << state;
  out << "\n";
  return out.str();
}

std::string status_json(const WorkspaceStatus& status) {
  using nlohmann::json;
  json stages = json::array();
  std::map<std::string, int> totals;
  for (const auto& stage : status.stages) {
    json shards = json::array();
    for (const auto& shard : stage.shards) {
      ++totals[shard.state];
      shards.push_back({{"shard", shard.shard},
                        {"state", shard.state},
                        {"reason", shard.reason},
                        {"log", shard.log},
                        {"finished", shard.finished},
                        {"seconds", shard.seconds},
                        {"dataset_gaps", shard.dataset_gaps},
                        {"cluster_job", shard.cluster_job}});
    }
    stages.push_back({{"stage", stage.name},
                      {"kind", stage.kind},
                      {"available", stage.available},
                      {"unavailable_reason", stage.unavailable_reason},
                      {"shards", shards}});
  }
  const json j = {{"workspace", status.workspace.string()},
                  {"config", status.config.string()},
                  {"run_in_progress", status.run_in_progress},
                  {"stages", stages},
                  {"totals", totals}};
  return j.dump(2) + "\n";
}

}  // namespace tega::pipeline
