#pragma once
// A committed shard's manifest, WORKSPACE/<stage>/<shard>/manifest.json: what
// it was made from (its fingerprint), how, when, and the hash of every file it
// holds. It is written into the staging directory before the directory is
// renamed into place, so a shard directory is complete or absent.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tega/pipeline/fingerprint.h"

namespace tega::pipeline {

inline constexpr const char* kManifestFile = "manifest.json";
// In the staging directory of a shard whose kind resumes there: the
// fingerprint key its partial outputs were made for. Not an output: removed
// once the commit has renamed the directory into place.
inline constexpr const char* kResumeKeyFile = ".resume-key";

struct OutputFile {
  std::string path;  // relative to the shard directory, '/'-separated
  uint64_t size = 0;
  std::string sha256;
};

struct Manifest {
  std::string stage, shard, kind;
  Fingerprint fingerprint;
  std::string key;                   // fingerprint.key() when written
  std::vector<std::string> command;  // as run (paths point into the staging directory)
  std::string log;                   // the shard's log file
  std::string started, finished;     // UTC, ISO 8601
  double seconds = 0;
  double peak_rss_mib = 0;           // the command's largest resident memory (a split shard's largest job's); 0: unknown
  std::vector<OutputFile> outputs;   // every file of the shard but the manifest, sorted
  std::string output_hash;           // hash of `outputs`: what downstream fingerprints see
};

// Hashes every file under `shard_dir` except the manifest.
std::vector<OutputFile> hash_outputs(const std::filesystem::path& shard_dir);
std::string outputs_hash(const std::vector<OutputFile>& outputs);

void write_manifest(const std::filesystem::path& file, const Manifest& manifest);
// nullopt when the file is absent; throws tega::Error naming it when it is unreadable.
std::optional<Manifest> read_manifest(const std::filesystem::path& file);

// "" when every output the manifest lists is present with its size; else the
// first that is not (sizes only: re-hashing big outputs on every run is too slow).
std::string damaged_output(const std::filesystem::path& shard_dir, const Manifest& manifest);

std::string utc_now();  // ISO 8601, second precision

}  // namespace tega::pipeline
