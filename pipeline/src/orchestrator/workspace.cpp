#include "tega/pipeline/workspace.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/pipeline/manifest.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
constexpr const char* kStagingPrefix = ".staging-";
constexpr const char* kReplacedPrefix = ".replaced-";
}  // namespace

Workspace::Workspace(fs::path root) : root_(std::move(root)) {}

fs::path Workspace::shard_dir(const std::string& stage, const std::string& shard) const { return root_ / stage / shard; }

fs::path Workspace::staging_dir(const std::string& stage, const std::string& shard) const {
  return root_ / stage / (kStagingPrefix + shard);
}

fs::path Workspace::manifest_file(const std::string& stage, const std::string& shard) const {
  return shard_dir(stage, shard) / kManifestFile;
}

fs::path Workspace::state_file(const std::string& stage, const std::string& shard) const {
  return root_ / stage / (shard + ".state.json");
}

fs::path Workspace::log_file(const std::string& stage, const std::string& shard) const {
  return root_ / "logs" / stage / (shard + ".log");
}

fs::path Workspace::config_record() const { return root_ / "pipeline.json"; }

void Workspace::remove_leftovers(const std::vector<std::string>& stages) const {
  for (const auto& stage : stages) {
    const fs::path folder = root_ / stage;
    if (!fs::is_directory(folder)) continue;
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      // A resumable shard's partial outputs stay; its launch keeps them only for the same fingerprint.
      if (name.rfind(kStagingPrefix, 0) == 0 && fs::exists(entry.path() / kResumeKeyFile)) continue;
      if (name.rfind(kStagingPrefix, 0) == 0 || name.rfind(kReplacedPrefix, 0) == 0) remove_tree(entry.path());
    }
  }
}

void Workspace::commit(const std::string& stage, const std::string& shard) const {
  const fs::path final_dir = shard_dir(stage, shard);
  const fs::path replaced = root_ / stage / (kReplacedPrefix + shard);
  if (fs::exists(final_dir)) {
    remove_tree(replaced);
    fs::rename(final_dir, replaced);
  }
  fs::rename(staging_dir(stage, shard), final_dir);
  remove_tree(replaced);
}

WorkspaceLock::WorkspaceLock(const fs::path& root) {
  fs::create_directories(root);
  const fs::path file = root / ".lock";
  // O_CLOEXEC: shard processes must not inherit the lock, or a killed run's
  // children would keep the workspace locked.
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(file, "cannot be opened");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    throw Error(root, "another `tega run` is using this workspace");
  }
}

WorkspaceLock::~WorkspaceLock() {
  if (fd_ >= 0) ::close(fd_);
}

bool run_in_progress(const fs::path& root) {
  const int fd = ::open((root / ".lock").c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0;
  ::close(fd);
  return held;
}

void write_shard_state(const fs::path& file, const ShardState& s) {
  const json j = {{"state", s.state}, {"error", s.error}, {"log", s.log}, {"started", s.started}, {"finished", s.finished}};
  write_text_atomic(file, j.dump(2) + "\n");
}

std::optional<ShardState> read_shard_state(const fs::path& file) {
  if (!fs::exists(file)) return std::nullopt;
  try {
    const json j = json::parse(read_text_file(file));
    return ShardState{j.at("state"), j.at("error"), j.at("log"), j.at("started"), j.at("finished")};
  } catch (const std::exception&) {
    return std::nullopt;  // written atomically, so only a hand-edited file gets here: treat as absent
  }
}

}  // namespace tega::pipeline
