#include "tega/pipeline/manifest.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/pipeline/sha256.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

std::vector<OutputFile> hash_outputs(const fs::path& shard_dir) {
  std::vector<OutputFile> outputs;
  if (!fs::exists(shard_dir)) return outputs;
  for (const auto& entry : fs::recursive_directory_iterator(shard_dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string relative = fs::relative(entry.path(), shard_dir).generic_string();
    if (relative == kManifestFile || relative == kResumeKeyFile) continue;
    outputs.push_back({relative, entry.file_size(), sha256_file(entry.path())});
  }
  std::sort(outputs.begin(), outputs.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
  return outputs;
}

std::string outputs_hash(const std::vector<OutputFile>& outputs) {
  Sha256 hash;
  for (const auto& o : outputs) hash.update(o.path + "\t" + std::to_string(o.size) + "\t" + o.sha256 + "\n");
  return hash.hex_digest();
}

void write_manifest(const fs::path& file, const Manifest& m) {
  json inputs = json::array();
  for (const auto& [name, hash] : m.fingerprint.inputs) inputs.push_back({{"input", name}, {"hash", hash}});
  json outputs = json::array();
  for (const auto& o : m.outputs) outputs.push_back({{"path", o.path}, {"size", o.size}, {"sha256", o.sha256}});
  const nlohmann::ordered_json j = {{"format", "tega-shard-manifest"},
                  {"version", 1},
                  {"stage", m.stage},
                  {"shard", m.shard},
                  {"kind", m.kind},
                  {"key", m.key},
                  {"tool_version", m.fingerprint.tool_version},
                  {"options", m.fingerprint.options_yaml},
                  {"inputs", inputs},
                  {"command", m.command},
                  {"log", m.log},
                  {"started", m.started},
                  {"finished", m.finished},
                  {"seconds", m.seconds},
                  {"peak_rss_mib", m.peak_rss_mib},
                  {"output_hash", m.output_hash},
                  {"outputs", outputs}};
  write_text_atomic(file, j.dump(2) + "\n");
}

std::optional<Manifest> read_manifest(const fs::path& file) {
  if (!fs::exists(file)) return std::nullopt;
  try {
    const json j = json::parse(read_text_file(file));
    if (j.at("format") != "tega-shard-manifest") throw Error(file, "is not a tega shard manifest");
    Manifest m;
    m.stage = j.at("stage");
    m.shard = j.at("shard");
    m.kind = j.at("kind");
    m.key = j.at("key");
    m.fingerprint.tool_version = j.at("tool_version");
    m.fingerprint.options_yaml = j.at("options");
    for (const auto& in : j.at("inputs")) m.fingerprint.inputs.emplace_back(in.at("input"), in.at("hash"));
    m.command = j.at("command").get<std::vector<std::string>>();
    m.log = j.at("log");
    m.started = j.at("started");
    m.finished = j.at("finished");
    m.seconds = j.at("seconds");
    m.peak_rss_mib = j.value("peak_rss_mib", 0.0);  // absent from manifests written before it was recorded
    m.output_hash = j.at("output_hash");
    for (const auto& o : j.at("outputs")) m.outputs.push_back({o.at("path"), o.at("size"), o.at("sha256")});
    return m;
  } catch (const json::exception& e) {
    throw Error(file, std::string("is not a valid shard manifest: ") + e.what());
  }
}

std::string damaged_output(const fs::path& shard_dir, const Manifest& manifest) {
  for (const auto& o : manifest.outputs) {
    const fs::path file = shard_dir / o.path;
    std::error_code ec;
    const auto size = fs::file_size(file, ec);
    if (ec) return o.path + " is missing";
    if (size != o.size) return o.path + " changed size";
  }
  return "";
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace tega::pipeline
