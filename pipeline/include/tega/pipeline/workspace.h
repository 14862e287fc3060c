#pragma once
// The workspace of a pipeline (docs/pipeline.md#workspace):
//
//   WORKSPACE/pipeline.json                the config of the latest run (for `tega status`)
//   WORKSPACE/.lock                        held (flock) by the `tega run` using the workspace
//   WORKSPACE/<stage>/<shard>/             a committed shard: manifest.json + its outputs
//   WORKSPACE/<stage>/.staging-<shard>/    a shard being produced (a later run removes leftovers)
//   WORKSPACE/<stage>/<shard>.state.json   a shard that is running, failed or was interrupted
//   WORKSPACE/logs/<stage>/<shard>.log     the shard's command output, every attempt appended

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tega::pipeline {

class Workspace {
 public:
  explicit Workspace(std::filesystem::path root);

  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path shard_dir(const std::string& stage, const std::string& shard) const;
  std::filesystem::path staging_dir(const std::string& stage, const std::string& shard) const;
  std::filesystem::path manifest_file(const std::string& stage, const std::string& shard) const;
  std::filesystem::path state_file(const std::string& stage, const std::string& shard) const;
  std::filesystem::path log_file(const std::string& stage, const std::string& shard) const;
  std::filesystem::path config_record() const;

  // Removes what an interrupted run left behind in these stages' folders:
  // staging directories and shard directories that were being replaced.
  void remove_leftovers(const std::vector<std::string>& stages) const;

  // Moves the staging directory (which already holds its manifest) onto the
  // shard directory, replacing an older one. Each step is a rename: a crash
  // leaves the old shard, no shard, or the new shard, never a mixture.
  void commit(const std::string& stage, const std::string& shard) const;

 private:
  std::filesystem::path root_;
};

// An exclusive flock on WORKSPACE/.lock for the life of the object. The kernel
// releases it when the process dies, however it dies.
class WorkspaceLock {
 public:
  explicit WorkspaceLock(const std::filesystem::path& root);  // throws tega::Error when another run holds it
  ~WorkspaceLock();
  WorkspaceLock(const WorkspaceLock&) = delete;
  WorkspaceLock& operator=(const WorkspaceLock&) = delete;

 private:
  int fd_ = -1;
};

bool run_in_progress(const std::filesystem::path& root);  // whether a `tega run` holds the lock

struct ShardState {
  std::string state;  // running, failed or interrupted
  std::string error;  // for failed and interrupted shards
  std::string log;
  std::string started, finished;
};

void write_shard_state(const std::filesystem::path& file, const ShardState& state);
std::optional<ShardState> read_shard_state(const std::filesystem::path& file);  // nullopt when absent or unreadable

}  // namespace tega::pipeline
