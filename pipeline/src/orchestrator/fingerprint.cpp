#include "tega/pipeline/fingerprint.h"

#include <algorithm>

#include "tega/core/error.h"
#include "tega/pipeline/sha256.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
namespace {

void add_field(Sha256& hash, const std::string& text) {
  // Length-prefixed, so that no two different field lists hash the same bytes.
  hash.update(std::to_string(text.size()) + ":");
  hash.update(text);
}

std::string file_entry(const fs::path& file, const std::string& name) {
  const auto mtime = fs::last_write_time(file).time_since_epoch();
  return name + "\t" + std::to_string(fs::file_size(file)) + "\t" +
         std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(mtime).count()) + "\n";
}

}  // namespace

std::string Fingerprint::key() const {
  Sha256 hash;
  add_field(hash, tool_version);
  add_field(hash, options_yaml);
  for (const auto& [name, value] : inputs) {
    add_field(hash, name);
    add_field(hash, value);
  }
  return hash.hex_digest();
}

std::string listing_hash(const fs::path& path) {
  if (!fs::exists(path)) throw Error(path, "does not exist");
  if (fs::is_regular_file(path)) return sha256_hex(file_entry(path, path.filename().string()));
  std::vector<std::string> entries;
  for (const auto& entry : fs::recursive_directory_iterator(path)) {
    if (entry.is_regular_file()) entries.push_back(file_entry(entry.path(), fs::relative(entry.path(), path).string()));
  }
  std::sort(entries.begin(), entries.end());
  Sha256 hash;
  for (const auto& e : entries) hash.update(e);
  return hash.hex_digest();
}

Fingerprint fingerprint_shard(const StageGraph& graph, size_t stage_index, size_t subject_index,
                              const std::string& tool_version, const OutputHashOf& output_hash_of) {
  const Stage& stage = graph.stages()[stage_index];
  const PipelineConfig& config = graph.config();
  const SubjectConfig& subject = config.subjects[subject_index];

  Fingerprint fp;
  fp.tool_version = tool_version;
  fp.options_yaml = config.options_for(*stage.config, subject);
  for (size_t in : stage.inputs) {
    fp.inputs.emplace_back(graph.stages()[in].name() + "/" + subject.name, output_hash_of(in, subject_index));
  }
  // More GPUs a step are more views a step: another training.
  if (stage.config->gpus_per_job > 1) fp.inputs.emplace_back("gpus_per_job", std::to_string(stage.config->gpus_per_job));
  if (stage.kind->split_changes_outputs && stage.config->frames_per_job > 0)
    fp.inputs.emplace_back("frames_per_job", std::to_string(stage.config->frames_per_job));
  if (stage.kind->reads_capture) {
    if (subject.capture.empty()) {
      throw Error(config.source, "stage '" + stage.name() + "' (kind " + stage.kind->name + ") reads a capture: subject '" +
                                     subject.name + "' needs 'capture: DIR'");
    }
    fp.inputs.emplace_back("capture", listing_hash(subject.capture));
  }
  for (const auto& option : stage.kind->path_options) {
    const auto value = scalar_option(fp.options_yaml, option);
    if (!value || value->empty()) continue;
    const fs::path path = (config.base_dir / *value).lexically_normal();
    try {
      fp.inputs.emplace_back("option " + option, listing_hash(path));
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (option '" + option + "' of stage '" + stage.name() + "', subject '" +
                  subject.name + "')");
    }
  }
  return fp;
}

}  // namespace tega::pipeline
