#pragma once
// The stage graph of a config: stages in dependency order, each with its kind,
// its upstream stages and where each artifact it needs comes from. Every
// stage has one shard per subject (docs/pipeline.md#shards).

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "tega/pipeline/config.h"
#include "tega/pipeline/stage_kinds.h"

namespace tega::pipeline {

// Whether the running `tega` binary has a subcommand, e.g. {"dataset", "check"}.
using CommandAvailable = std::function<bool(const std::vector<std::string>& subcommand)>;

struct Stage {
  const StageConfig* config = nullptr;
  const StageKind* kind = nullptr;
  std::vector<size_t> upstream;                   // the stages named in `after`
  std::map<std::string, size_t> artifact_source;  // needed artifact -> the stage providing it
  std::vector<size_t> inputs;                     // upstream and artifact sources: what a shard depends on
  bool available = true;
  std::string unavailable_reason;                 // "not implemented in tega yet", ...

  const std::string& name() const { return config->name; }
};

class StageGraph {
 public:
  // Throws tega::Error naming the config file for an unknown kind or stage,
  // a cycle, or an artifact no upstream stage provides.
  StageGraph(PipelineConfig config, const CommandAvailable& available);
  StageGraph(const StageGraph&) = delete;
  StageGraph& operator=(const StageGraph&) = delete;

  const PipelineConfig& config() const { return config_; }
  const std::vector<Stage>& stages() const { return stages_; }  // dependencies first
  size_t index_of(const std::string& stage_name) const;         // throws tega::Error listing the stages
  std::vector<bool> downstream_of(size_t stage) const;          // the stage and all that depend on it
  std::vector<bool> upstream_of(const std::vector<bool>& stages) const;  // those and all they depend on

 private:
  PipelineConfig config_;
  std::vector<Stage> stages_;
};

}  // namespace tega::pipeline
