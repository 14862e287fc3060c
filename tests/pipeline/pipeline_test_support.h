#pragma once
// Runs the real `tega` binary for the orchestrator's tests, and inspects
// workspaces: committed outputs, shard attempts, processes still at work.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace tega::test {

struct TegaResult {
  int exit_code = -1;  // -1: killed by a signal
  std::string output;  // stdout and stderr together
};

// Starts `tega ARGS...` with stdout and stderr going to `output_file`.
pid_t spawn_tega(const std::vector<std::string>& args, const std::filesystem::path& output_file);
// Waits for a spawned process; exit_code is -1 if a signal killed it.
int wait_for_exit(pid_t pid);
TegaResult run_tega(const std::vector<std::string>& args, const std::filesystem::path& scratch_dir);

bool tega_has_command(const std::vector<std::string>& subcommand);

// Synth options small enough that a shard takes about a second.
std::string tiny_synth_options(int indent);

// Every file of every committed shard (a directory holding manifest.json),
// "stage/shard/path" -> SHA-256, and "stage/shard/ (output hash)" -> the
// manifest's output hash; manifests themselves are left out (they hold timestamps).
std::map<std::string, std::string> committed_outputs(const std::filesystem::path& workspace);
// Shard directories, staging or not, that have no manifest.
std::vector<std::string> shard_dirs_without_manifest(const std::filesystem::path& workspace);
std::vector<std::string> staging_dirs(const std::filesystem::path& workspace);

// How many times the shard's command was started (one header line per attempt in its log).
int attempts(const std::filesystem::path& workspace, const std::string& stage, const std::string& shard);

// Whether a process other than this one has `text` on its command line.
bool process_mentions(const std::string& text);
bool wait_until_no_process_mentions(const std::string& text, std::chrono::milliseconds timeout);

}  // namespace tega::test
