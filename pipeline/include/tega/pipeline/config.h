#pragma once
// A pipeline config (docs/pipeline.md#configs): the workspace, the subjects
// and the stages in graph order, each with its options. Loading is strict: an
// unknown key is an error naming the file, the key and the known keys.
// Relative paths in a config resolve against the config file's directory, so
// a config means the same thing from wherever it is run.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace tega::pipeline {

struct StageConfig {
  std::string name;                // the key under `stages`
  std::string kind;                // `kind`, default: the name (docs/pipeline.md#stage-kinds)
  std::vector<std::string> after;  // upstream stages
  // `frames_per_job: N`: each shard runs as several jobs at once, each on at most N frames of
  // one take (kinds with StageKind::split only); 0: one job a shard.
  int frames_per_job = 0;
  // `gpus_per_job: N`: each shard runs on N GPUs at once (kinds with StageKind::gpus_flag only:
  // train, data parallel), with the stage's device `cuda`; 1: one GPU, as any GPU stage.
  int gpus_per_job = 1;
  // `jobs_per_gpu: K`: up to K of this stage's jobs share one GPU in a local run (GPU stages
  // only; not with gpus_per_job), so that one job's GPU work overlaps another's CPU work.
  int jobs_per_gpu = 1;
  // `options_file` (a file in the command's own --config format) with
  // `options` merged over it; canonical YAML, "" = none.
  std::string options_yaml;
};

struct SubjectConfig {
  std::string name;
  std::filesystem::path capture;                     // absolute; empty = none
  std::map<std::string, std::string> stage_options;  // stage -> canonical YAML merged over its options
};

struct PipelineConfig {
  std::filesystem::path source;    // the file, named in errors
  std::filesystem::path base_dir;  // where relative paths resolve (absolute)
  std::string text;                // the file as read (recorded in the workspace for `tega status`)
  std::filesystem::path workspace;
  std::vector<SubjectConfig> subjects;  // never empty: one subject "default" when the config has none
  std::vector<StageConfig> stages;      // in file order
  // `gpus: [0, 1]`: the GPUs a local run spreads its GPU shards over (CUDA_VISIBLE_DEVICES
  // entries, gpus.h); unset: every GPU of the machine. `tega run --gpus` overrides it.
  std::optional<std::vector<std::string>> gpus;

  // The options of `stage` for `subject`: the stage's, with the subject's overlay merged in.
  std::string options_for(const StageConfig& stage, const SubjectConfig& subject) const;
};

PipelineConfig load_pipeline_config(const std::filesystem::path& file);  // throws tega::Error naming the file
PipelineConfig parse_pipeline_config(const std::string& text, const std::filesystem::path& source,
                                     const std::filesystem::path& base_dir);

// Options as the text of a --config file that reads them from `section` ("" = the whole document).
std::string options_file_text(const std::string& options_yaml, const std::string& section);

// Options as command-line flags: `key: value` -> --key value (underscores
// become hyphens), `key: true` -> --key, `key: false` -> nothing, a list ->
// the flag once per item. Throws tega::Error for a mapping value.
std::vector<std::string> option_flags(const std::string& options_yaml);
std::vector<std::string> option_keys(const std::string& options_yaml);  // the top-level keys

// The value of a scalar option (dotted key: "loss.vgg_weights") in options YAML, if set.
std::optional<std::string> scalar_option(const std::string& options_yaml, const std::string& dotted_key);

}  // namespace tega::pipeline
