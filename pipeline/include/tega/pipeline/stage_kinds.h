#pragma once
// What a stage of each kind does: the `tega` subcommand a shard runs, the
// artifacts it needs from upstream stages and the ones it provides, and the
// external inputs it reads (docs/pipeline.md#stage-kinds). Adding a stage is
// adding a kind here; neither the orchestrator nor the executors change.

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace tega::pipeline {

// Where one shard's command reads and writes; every path is absolute.
struct ShardPaths {
  std::filesystem::path output;        // the shard's staging directory: outputs go under it
  std::filesystem::path options_file;  // OptionsAs::config_file: the stage's options as a YAML file
  std::vector<std::string> option_flags;  // OptionsAs::flags: the stage's options as flags
  std::map<std::string, std::filesystem::path> artifacts;  // each needed artifact -> its path
  std::filesystem::path capture;       // the subject's capture directory (kinds that read one)
};

// How a shard's command receives the stage's options.
enum class OptionsAs {
  none,         // the command takes no options
  config_file,  // --config FILE, a YAML file (under `options_section` when that is set)
  flags,        // each option `key: value` becomes `--key value` (see option_flags())
};

struct StageKind {
  std::string name;
  std::string summary;
  // The `tega` subcommand a shard runs, e.g. {"dataset", "check"}. Empty:
  // the stage is not implemented in tega yet and is reported as such.
  std::vector<std::string> subcommand;
  std::vector<std::string> needs;                        // artifacts taken from upstream stages
  std::vector<std::string> optional_needs;               // taken where a stage upstream provides them
  std::map<std::string, std::string> provides;           // artifact -> path inside the shard directory
  OptionsAs options_as = OptionsAs::config_file;
  std::string options_section;                           // config_file: the section the command reads, "" = all
  std::vector<std::string> flag_options;                 // flags: the options the command has
  bool reads_capture = false;                            // the subject's `capture` is an input
  std::vector<std::string> path_options;                 // options that name external input files
  std::string device_option;                             // option naming the device ("cuda..." = a GPU stage)
  // The command keeps what it finished in its output and skips it when run
  // again (e.g. per-frame meshes): a shard interrupted and started again with
  // the same fingerprint keeps its staging directory instead of starting over.
  bool resumes_in_staging = false;
  std::function<std::vector<std::string>(const ShardPaths&)> arguments;  // after the subcommand
  // How a shard splits into jobs that run at once (the stage's `frames_per_job`): each job's
  // arguments after `arguments`' (e.g. --take T --frames A:B). The jobs write disjoint files
  // into the one staging directory, which is committed when all of them have succeeded. Empty:
  // the kind does not split.
  std::function<std::vector<std::vector<std::string>>(const ShardPaths&, int frames_per_job)> split;
  // Whether the split changes the outputs (track fits each range's first frame afresh): then
  // `frames_per_job` is part of the shard's fingerprint.
  bool split_changes_outputs = false;
  // The flag through which the command spreads one shard over several GPUs (the stage's
  // `gpus_per_job`), given the GPUs the job sees as "0,1,...". Empty: the kind uses one GPU.
  std::string gpus_flag;
};

const std::vector<StageKind>& stage_kinds();
const StageKind* find_stage_kind(std::string_view name);  // nullptr when unknown

}  // namespace tega::pipeline
