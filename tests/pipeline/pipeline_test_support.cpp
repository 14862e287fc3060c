#include "pipeline_test_support.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "tega/core/files.h"
#include "tega/pipeline/manifest.h"
#include "tega/pipeline/sha256.h"

extern char** environ;

namespace tega::test {
namespace fs = std::filesystem;

pid_t spawn_tega(const std::vector<std::string>& args, const fs::path& output_file) {
  std::vector<std::string> argv_strings = {TEGA_EXECUTABLE};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, output_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

int wait_for_exit(pid_t pid) {
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return -2;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TegaResult run_tega(const std::vector<std::string>& args, const fs::path& scratch_dir) {
  static int counter = 0;
  const fs::path output = scratch_dir / ("tega-output-" + std::to_string(counter++) + ".txt");
  TegaResult result;
  result.exit_code = wait_for_exit(spawn_tega(args, output));
  result.output = read_text_file(output);
  return result;
}

bool tega_has_command(const std::vector<std::string>& subcommand) {
  std::vector<std::string> args = subcommand;
  args.push_back("--help");
  return wait_for_exit(spawn_tega(args, "/dev/null")) == 0;
}

std::string tiny_synth_options(int indent) {
  const std::string pad(indent, ' ');
  return pad + "studio: {cameras: 2, width: 64, height: 48}\n" + pad + "frames: 2\n" + pad +
         "calibration_frames: 1\n" + pad + "takes: [expressions, freestyle]\n" + pad + "test_takes: [freestyle]\n" +
         pad + "test_cameras: 1\n" + pad + "supersampling: 1\n" + pad + "fine_subdivisions: 0\n" + pad +
         "write_fine_meshes: false\n" + pad + "threads: 1\n";
}

namespace {

std::vector<fs::path> stage_folders(const fs::path& workspace) {
  std::vector<fs::path> out;
  if (!fs::exists(workspace)) return out;
  for (const auto& e : fs::directory_iterator(workspace)) {
    if (e.is_directory() && e.path().filename() != "logs") out.push_back(e.path());
  }
  return out;
}

}  // namespace

std::map<std::string, std::string> committed_outputs(const fs::path& workspace) {
  std::map<std::string, std::string> out;
  for (const auto& stage : stage_folders(workspace)) {
    for (const auto& shard : fs::directory_iterator(stage)) {
      if (!shard.is_directory() || !fs::exists(shard.path() / "manifest.json")) continue;
      const std::string shard_name = fs::relative(shard.path(), workspace).generic_string();
      out[shard_name + "/ (output hash)"] = pipeline::read_manifest(shard.path() / "manifest.json")->output_hash;
      for (const auto& file : fs::recursive_directory_iterator(shard.path())) {
        if (!file.is_regular_file() || file.path().filename() == "manifest.json") continue;
        out[fs::relative(file.path(), workspace).generic_string()] = pipeline::sha256_file(file.path());
      }
    }
  }
  return out;
}

std::vector<std::string> shard_dirs_without_manifest(const fs::path& workspace) {
  std::vector<std::string> out;
  for (const auto& stage : stage_folders(workspace)) {
    for (const auto& shard : fs::directory_iterator(stage)) {
      const std::string name = shard.path().filename().string();
      if (shard.is_directory() && name[0] != '.' && !fs::exists(shard.path() / "manifest.json")) {
        out.push_back(fs::relative(shard.path(), workspace).string());
      }
    }
  }
  return out;
}

std::vector<std::string> staging_dirs(const fs::path& workspace) {
  std::vector<std::string> out;
  for (const auto& stage : stage_folders(workspace)) {
    for (const auto& shard : fs::directory_iterator(stage)) {
      if (shard.path().filename().string()[0] == '.') out.push_back(fs::relative(shard.path(), workspace).string());
    }
  }
  return out;
}

int attempts(const fs::path& workspace, const std::string& stage, const std::string& shard) {
  std::ifstream log(workspace / "logs" / stage / (shard + ".log"));
  int n = 0;
  for (std::string line; std::getline(log, line);) n += line.rfind("=== ", 0) == 0 ? 1 : 0;
  return n;
}

bool process_mentions(const std::string& text) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos || name == std::to_string(::getpid())) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::stringstream cmdline;
    cmdline << in.rdbuf();
    if (cmdline.str().find(text) != std::string::npos) return true;
  }
  return false;
}

bool wait_until_no_process_mentions(const std::string& text, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (process_mentions(text)) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

}  // namespace tega::test
