#include "tega/pipeline/stage_graph.h"

#include <algorithm>
#include <deque>
#include <set>

#include "tega/core/error.h"

namespace tega::pipeline {
namespace {

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::string known_kinds() {
  std::vector<std::string> names;
  for (const auto& kind : stage_kinds()) names.push_back(kind.name);
  return join(names, ", ");
}

// Options a command could not take are config errors, found before anything runs.
void check_options(const PipelineConfig& config, const StageConfig& stage, const StageKind& kind) {
  std::vector<std::string> sources = {stage.options_yaml};
  for (const auto& subject : config.subjects) {
    if (subject.stage_options.count(stage.name)) sources.push_back(subject.stage_options.at(stage.name));
  }
  const std::string what = "stage '" + stage.name + "' (kind " + kind.name + ")";
  for (const auto& options : sources) {
    if (kind.options_as == OptionsAs::none && !options.empty()) throw Error(config.source, what + " takes no options");
    if (kind.options_as != OptionsAs::flags) continue;
    for (const auto& key : option_keys(options)) {
      if (std::find(kind.flag_options.begin(), kind.flag_options.end(), key) == kind.flag_options.end()) {
        throw Error(config.source, what + ": unknown option '" + key + "'; known options: " + join(kind.flag_options, ", "));
      }
    }
  }
}

}  // namespace

StageGraph::StageGraph(PipelineConfig config, const CommandAvailable& available) : config_(std::move(config)) {
  const auto& source = config_.source;
  const size_t n = config_.stages.size();
  std::map<std::string, size_t> by_name;
  for (size_t i = 0; i < n; ++i) by_name[config_.stages[i].name] = i;

  // Resolve kinds and `after` in file order, then sort dependencies first.
  std::vector<Stage> in_file_order(n);
  for (size_t i = 0; i < n; ++i) {
    const StageConfig& sc = config_.stages[i];
    Stage& stage = in_file_order[i];
    stage.config = &sc;
    stage.kind = find_stage_kind(sc.kind);
    if (!stage.kind) {
      throw Error(source, "stage '" + sc.name + "': unknown kind '" + sc.kind + "'; known kinds: " + known_kinds());
    }
    check_options(config_, sc, *stage.kind);
    if (sc.frames_per_job > 0 && !stage.kind->split) {
      throw Error(source, "stage '" + sc.name + "': frames_per_job: a " + stage.kind->name +
                              " shard runs as one job (only mvs, track and matte split into jobs)");
    }
    if (sc.gpus_per_job > 1 && stage.kind->gpus_flag.empty()) {
      throw Error(source, "stage '" + sc.name + "': gpus_per_job: a " + stage.kind->name +
                              " shard runs on one GPU (only train spreads a shard over several)");
    }
    if (sc.jobs_per_gpu > 1 && stage.kind->device_option.empty()) {
      throw Error(source, "stage '" + sc.name + "': jobs_per_gpu: a " + stage.kind->name + " shard runs on the CPU");
    }
    if (sc.jobs_per_gpu > 1 && sc.gpus_per_job > 1) {
      throw Error(source, "stage '" + sc.name + "': jobs_per_gpu and gpus_per_job together: a job of several GPUs "
                              "holds them alone");
    }
    for (const auto& up : sc.after) {
      const auto it = by_name.find(up);
      if (it == by_name.end()) throw Error(source, "stage '" + sc.name + "': 'after' names no stage: '" + up + "'");
      if (it->second == i) throw Error(source, "stage '" + sc.name + "' cannot come after itself");
      stage.upstream.push_back(it->second);
    }
  }

  std::vector<size_t> order;
  std::vector<int> mark(n, 0);  // 0 unvisited, 1 on the path, 2 placed
  std::function<void(size_t, std::vector<std::string>&)> place = [&](size_t i, std::vector<std::string>& path) {
    if (mark[i] == 2) return;
    path.push_back(config_.stages[i].name);
    if (mark[i] == 1) throw Error(source, "the stages' 'after' lists form a cycle: " + join(path, " -> "));
    mark[i] = 1;
    for (size_t up : in_file_order[i].upstream) place(up, path);
    mark[i] = 2;
    path.pop_back();
    order.push_back(i);
  };
  for (size_t i = 0; i < n; ++i) {
    std::vector<std::string> path;
    place(i, path);
  }

  std::vector<size_t> position(n);
  for (size_t k = 0; k < n; ++k) position[order[k]] = k;
  for (size_t k = 0; k < n; ++k) {
    Stage stage = in_file_order[order[k]];
    for (auto& up : stage.upstream) up = position[up];
    stages_.push_back(std::move(stage));
  }

  for (Stage& stage : stages_) {
    // Each artifact comes from the nearest stage upstream that provides it.
    const auto find_source = [&](const std::string& artifact) {
      std::deque<size_t> queue(stage.upstream.begin(), stage.upstream.end());
      std::set<size_t> seen;
      while (!queue.empty()) {
        const size_t s = queue.front();
        queue.pop_front();
        if (!seen.insert(s).second) continue;
        if (stages_[s].kind->provides.count(artifact)) {
          stage.artifact_source[artifact] = s;
          return;
        }
        queue.insert(queue.end(), stages_[s].upstream.begin(), stages_[s].upstream.end());
      }
    };
    for (const auto& artifact : stage.kind->optional_needs) find_source(artifact);
    for (const auto& artifact : stage.kind->needs) {
      find_source(artifact);
      if (!stage.artifact_source.count(artifact)) {
        throw Error(source, "stage '" + stage.name() + "' (kind " + stage.kind->name + ") needs a " + artifact +
                                ", which none of the stages it comes after provides (list one in its 'after')");
      }
    }
    std::set<size_t> inputs(stage.upstream.begin(), stage.upstream.end());
    for (const auto& [artifact, s] : stage.artifact_source) inputs.insert(s);
    stage.inputs.assign(inputs.begin(), inputs.end());

    if (stage.kind->subcommand.empty()) {
      stage.available = false;
      stage.unavailable_reason = "not implemented in tega yet (" + stage.kind->summary + ")";
    } else if (!available(stage.kind->subcommand)) {
      stage.available = false;
      stage.unavailable_reason = "`tega " + join(stage.kind->subcommand, " ") + "` is not available in this build";
    }
  }
}

size_t StageGraph::index_of(const std::string& stage_name) const {
  for (size_t i = 0; i < stages_.size(); ++i) {
    if (stages_[i].name() == stage_name) return i;
  }
  std::vector<std::string> names;
  for (const auto& s : stages_) names.push_back(s.name());
  throw Error(config_.source, "has no stage '" + stage_name + "'; its stages: " + join(names, ", "));
}

std::vector<bool> StageGraph::downstream_of(size_t stage) const {
  std::vector<bool> out(stages_.size(), false);
  out[stage] = true;
  for (size_t i = stage + 1; i < stages_.size(); ++i) {
    for (size_t in : stages_[i].inputs) out[i] = out[i] || out[in];
  }
  return out;
}

std::vector<bool> StageGraph::upstream_of(const std::vector<bool>& stages) const {
  std::vector<bool> out = stages;
  for (size_t i = stages_.size(); i-- > 0;) {
    if (!out[i]) continue;
    for (size_t in : stages_[i].inputs) out[in] = true;
  }
  return out;
}

}  // namespace tega::pipeline
