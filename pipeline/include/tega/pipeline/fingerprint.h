#pragma once
// A shard's fingerprint: everything its outputs depend on. A committed shard
// whose manifest carries the current fingerprint's key is done; any change
// (options, an input, the tool version) re-runs it (docs/pipeline.md#manifests).

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "tega/pipeline/stage_graph.h"

namespace tega::pipeline {

struct Fingerprint {
  std::string tool_version;
  std::string options_yaml;
  // (input, hash): "synth/alice" -> the output hash in that shard's manifest;
  // "capture", "option head", ... -> the listing hash of an external input.
  std::vector<std::pair<std::string, std::string>> inputs;

  std::string key() const;  // SHA-256 of all of the above
};

// The output hash of the committed shard (stage, subject), which must be done.
using OutputHashOf = std::function<std::string(size_t stage, size_t subject)>;

// Throws tega::Error naming an external input that does not exist.
Fingerprint fingerprint_shard(const StageGraph& graph, size_t stage, size_t subject, const std::string& tool_version,
                              const OutputHashOf& output_hash_of);

// Hash of (relative path, size, modification time) of every file under
// `path` (or of the file itself): external inputs such as captures are too
// large to re-read on every run. Throws tega::Error when `path` does not exist.
std::string listing_hash(const std::filesystem::path& path);

}  // namespace tega::pipeline
