#include "tega/pipeline/slurm_executor.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/pipeline/slurm_batch.h"

extern char** environ;

namespace tega::pipeline {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct ProgramResult {
  int exit_code = -1;  // -1: it could not be started or a signal ended it
  std::string output;  // stdout and stderr together
};

// Runs a Slurm client command from an argument vector (no shell ever sees the job's strings), in a
// process group of its own so that a terminal's Ctrl-C reaches only the orchestrator, which then
// cancels the jobs.
ProgramResult run_program(const std::vector<std::string>& args) {
  ProgramResult result;
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    result.output = std::string("cannot create a pipe: ") + std::strerror(errno);
    return result;
  }
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t pid = -1;
  const int error = ::posix_spawn(&pid, argv[0], &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  ::close(pipe_fds[1]);
  if (error != 0) {
    ::close(pipe_fds[0]);
    result.output = args[0] + ": cannot be started: " + std::strerror(error);
    return result;
  }
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n > 0) result.output.append(buffer, static_cast<size_t>(n));
    if (n == 0 || (n < 0 && errno != EINTR)) break;
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string last_line(const std::string& text) {
  const auto end = text.find_last_not_of("\n");
  if (end == std::string::npos) return "(no output)";
  const auto start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
}

fs::path find_tool(const fs::path& bin_dir, const std::string& name) {
  if (!bin_dir.empty()) {
    if (::access((bin_dir / name).c_str(), X_OK) == 0) return bin_dir / name;
    throw Error(bin_dir / name, "is not an executable; the Slurm executor needs Slurm's client commands there");
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (!dir.empty() && ::access((fs::path(dir) / name).c_str(), X_OK) == 0) return fs::path(dir) / name;
  }
  throw Error(name + " was not found on PATH: the Slurm executor needs Slurm's client commands (sbatch, squeue, "
              "scancel; Debian: slurm-client) on this host");
}

// Slurm's job states that end a job (squeue --states=all keeps showing them for MinJobAge).
bool is_final(const std::string& state) {
  static const std::set<std::string> final_states = {"COMPLETED", "FAILED",   "CANCELLED",     "TIMEOUT",
                                                     "NODE_FAIL", "PREEMPTED", "BOOT_FAIL",    "OUT_OF_MEMORY",
                                                     "DEADLINE",  "REVOKED",   "SPECIAL_EXIT"};
  return final_states.count(state) > 0;
}

// Final states that another attempt would reach again, or that someone chose: not requeued.
bool is_deliberate_end(const std::string& state) {
  return state == "CANCELLED" || state == "TIMEOUT" || state == "OUT_OF_MEMORY" || state == "DEADLINE";
}

std::optional<int> read_exit_status(const fs::path& exit_file) {
  if (!fs::exists(exit_file)) return std::nullopt;
  try {
    return std::stoi(read_text_file(exit_file));
  } catch (const std::exception&) {
    return std::nullopt;  // written with tmp + mv, so never partial; unreadable means absent
  }
}

// In a job, CUDA_VISIBLE_DEVICES lists only its allocated GPUs, numbered from 0.
void check_gpu_device(const Job& job, int gpus_per_job) {
  const std::string& device = job.resources.gpu_device;
  const auto colon = device.find(':');
  if (colon == std::string::npos) return;
  int index = 0;
  try {
    index = std::stoi(device.substr(colon + 1));
  } catch (const std::exception&) {
    throw Error(job.id + ": device '" + device + "' has no GPU index after the colon");
  }
  if (index >= gpus_per_job) {
    throw Error(job.id + ": device '" + device + "' names GPU " + std::to_string(index) + " of its Slurm job, which has " +
                std::to_string(gpus_per_job) + " (--gpus-per-job); under Slurm use 'cuda' or 'cuda:0'");
  }
}

// sbatch reads %j, %u, ... in --output; %% is a literal %.
std::string slurm_filename(const fs::path& file) {
  std::string out;
  for (const char c : file.string()) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

// Runs sbatch --parsable and returns the job id it prints; throws naming `what` it submitted.
std::string submitted_job_id(const std::vector<std::string>& sbatch_args, const std::string& what) {
  const ProgramResult result = run_program(sbatch_args);
  // --parsable prints "<id>" or "<id>;<cluster>".
  const std::string id = result.output.substr(0, result.output.find_first_of(";\n"));
  if (result.exit_code != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    throw Error("sbatch failed for " + what + ": " + last_line(result.output));
  }
  return id;
}

std::string stage_of(const Job& job) { return job.id.substr(0, job.id.find('/')); }

bool same_resources(const Resources& a, const Resources& b) {
  return a.gpu_device == b.gpu_device && a.gpu_count == b.gpu_count;
}

// A job of several GPUs (a train shard's gpus_per_job) asks for them, at least --gpus-per-job.
int job_gpus(const Resources& resources, int gpus_per_job) { return std::max(gpus_per_job, resources.gpu_count); }

// Slurm's default MaxArraySize (1001) allows task indices 0 to 1000.
constexpr size_t kMaxArrayTasks = 1001;

// Jobs that one sbatch can run as an array: those of one stage asking for the same resources.
std::vector<std::vector<Job>> array_groups(std::vector<Job> jobs) {
  std::vector<std::vector<Job>> groups;
  for (Job& job : jobs) {
    auto group = std::find_if(groups.begin(), groups.end(), [&](const std::vector<Job>& g) {
      return g.size() < kMaxArrayTasks && stage_of(g.front()) == stage_of(job) &&
             same_resources(g.front().resources, job.resources);
    });
    if (group == groups.end()) group = groups.emplace(groups.end());
    group->push_back(std::move(job));
  }
  return groups;
}

std::string job_ids(const std::vector<Job>& jobs) {
  std::string ids;
  for (const Job& job : jobs) ids += (ids.empty() ? "" : ", ") + job.id;
  return ids;
}

const char* const kArrayScriptName = "slurm-array.sh";

// The file of Slurm's own output for array task `task`; "%A_%a" gives sbatch's pattern for them all.
std::string array_task_output_name(const std::string& task) { return "slurm-" + task + ".out"; }

// A plain job's Slurm output is its log; an array task's goes to a file of its own until it ends.
void append_to_log(const fs::path& slurm_output, const fs::path& log) {
  if (slurm_output.empty() || !fs::exists(slurm_output)) return;
  const std::string text = read_text_file(slurm_output);
  if (!text.empty()) std::ofstream(log, std::ios::app) << text;
  fs::remove(slurm_output);
}

}  // namespace

SlurmExecutor::SlurmExecutor(SlurmOptions options)
    : options_(std::move(options)),
      sbatch_(find_tool(options_.bin_dir, "sbatch")),
      squeue_(find_tool(options_.bin_dir, "squeue")),
      scancel_(find_tool(options_.bin_dir, "scancel")) {
  if (options_.gpus_per_job < 1) throw Error("--gpus-per-job must be at least 1 (it is " + std::to_string(options_.gpus_per_job) + ")");
  if (options_.max_requeues < 0) throw Error("--max-requeues must not be negative (it is " + std::to_string(options_.max_requeues) + ")");
}

SlurmExecutor::~SlurmExecutor() {
  try {
    cancel_all();
  } catch (const std::exception& e) {
    spdlog::error("tega run: could not cancel the Slurm jobs: {}", e.what());
  }
}

void SlurmExecutor::submit(Job job) { queue_.push_back(std::move(job)); }

void SlurmExecutor::prepare(const Job& job) const {
  check_gpu_device(job, job_gpus(job.resources, options_.gpus_per_job));
  fs::create_directories(job.log_file.parent_path());
  const SlurmJobFiles files = slurm_job_files(job.log_file);
  fs::remove(files.exit_file);
  write_text_atomic(files.script, batch_script(job, files.exit_file));
}

std::vector<std::string> SlurmExecutor::sbatch_arguments(const std::string& name, const std::string& output,
                                                         const Resources& resources) const {
  std::vector<std::string> args = {sbatch_.string(),
                                   "--parsable",
                                   "--job-name=" + name,
                                   "--output=" + output,
                                   "--error=" + output,
                                   "--open-mode=append",
                                   "--export=ALL",
                                   "--no-requeue"};  // requeues are ours: the shard is prepared afresh first
  if (!options_.partition.empty()) args.push_back("--partition=" + options_.partition);
  if (!resources.gpu_device.empty())
    args.push_back("--gres=gpu:" + std::to_string(job_gpus(resources, options_.gpus_per_job)));
  return args;
}

std::string SlurmExecutor::sbatch_job(const Job& job) const {
  std::vector<std::string> args =
      sbatch_arguments(options_.job_name_prefix + job.id, slurm_filename(job.log_file), job.resources);
  args.push_back(slurm_job_files(job.log_file).script.string());
  return submitted_job_id(args, job.id);
}

std::string SlurmExecutor::sbatch_array(const std::vector<Job>& jobs) const {
  const fs::path dir = jobs.front().log_file.parent_path();
  write_text_atomic(dir / kArrayScriptName, array_batch_script(jobs));
  std::vector<std::string> args =
      sbatch_arguments(options_.job_name_prefix + stage_of(jobs.front()),
                       slurm_filename(dir) + "/" + array_task_output_name("%A_%a"), jobs.front().resources);
  args.push_back("--array=0-" + std::to_string(jobs.size() - 1));
  args.push_back((dir / kArrayScriptName).string());
  return submitted_job_id(args, "the job array of " + job_ids(jobs));
}

void SlurmExecutor::submit_group(std::vector<Job>& group) {
  if (group.size() == 1) {
    const std::string slurm_id = sbatch_job(group.front());
    track(std::move(group.front()), slurm_id);
    return;
  }
  const std::string array_id = sbatch_array(group);
  const fs::path output_dir = group.front().log_file.parent_path();
  for (size_t task = 0; task < group.size(); ++task) {
    const std::string slurm_id = array_id + "_" + std::to_string(task);
    track(std::move(group[task]), slurm_id, output_dir / array_task_output_name(slurm_id));
  }
}

void SlurmExecutor::track(Job job, const std::string& slurm_id, fs::path slurm_output) {
  spdlog::info("{}: Slurm job {}", job.id, slurm_id);
  write_slurm_job_record(slurm_job_files(job.log_file).record, {slurm_id, "PENDING"});
  submitted_[slurm_id] = {std::move(job), "PENDING", Clock::now(), std::nullopt, std::move(slurm_output)};
}

void SlurmExecutor::submit_queued(std::vector<JobResult>& results) {
  const auto could_not_start = [&](const Job& job, const std::exception& e) {
    results.push_back({job.id, false, std::string("could not start: ") + e.what(), 0, false});
  };
  std::vector<Job> prepared;
  for (Job& job : queue_) {
    try {
      prepare(job);
      prepared.push_back(std::move(job));
    } catch (const std::exception& e) {
      could_not_start(job, e);
    }
  }
  queue_.clear();
  for (std::vector<Job>& group : array_groups(std::move(prepared))) {
    try {
      submit_group(group);
    } catch (const std::exception& e) {
      for (const Job& job : group) could_not_start(job, e);
    }
  }
}

std::optional<std::map<std::string, std::string>> SlurmExecutor::queue_states() const {
  std::set<std::string> jobs;  // an array's tasks are asked about by the array's id
  for (const auto& [slurm_id, job] : submitted_) jobs.insert(slurm_id.substr(0, slurm_id.find('_')));
  std::string ids;
  for (const auto& id : jobs) ids += (ids.empty() ? "" : ",") + id;
  // --array: a line per array task, "<array>_<task>", pending ones too (else shown as "<array>_[0-3]").
  const ProgramResult result = run_program(
      {squeue_.string(), "--noheader", "--array", "--states=all", "--format=%i|%T", "--jobs=" + ids});
  std::map<std::string, std::string> states;
  if (result.exit_code != 0) {
    // squeue fails outright when it knows none of the ids: every job is long over.
    if (result.output.find("Invalid job id") != std::string::npos) return states;
    spdlog::warn("tega run: squeue failed (will ask again): {}", last_line(result.output));
    return std::nullopt;
  }
  std::istringstream lines(result.output);
  for (std::string line; std::getline(lines, line);) {
    const auto bar = line.find('|');
    if (bar != std::string::npos) states[line.substr(0, bar)] = line.substr(bar + 1);
  }
  return states;
}

void SlurmExecutor::poll(std::vector<JobResult>& results) {
  const auto states = queue_states();
  if (!states) return;
  for (auto it = submitted_.begin(); it != submitted_.end();) {
    Submitted& job = it->second;
    const auto state = states->find(it->first);
    // A job squeue no longer knows ended long enough ago to be purged.
    const std::string now = state == states->end() ? "GONE" : state->second;
    if (now != job.state && !is_final(now) && now != "GONE") {
      write_slurm_job_record(slurm_job_files(job.job.log_file).record, {it->first, now});
    }
    job.state = now;
    if ((is_final(now) || now == "GONE") && conclude(job, it->first, results)) {
      fs::remove(slurm_job_files(job.job.log_file).record);
      it = submitted_.erase(it);
    } else {
      ++it;
    }
  }
}

bool SlurmExecutor::conclude(Submitted& job, const std::string& slurm_id, std::vector<JobResult>& results) {
  const auto status = read_exit_status(slurm_job_files(job.job.log_file).exit_file);
  if (!status) {
    if (!job.over_without_exit_file) job.over_without_exit_file = Clock::now();
    if (Clock::now() - *job.over_without_exit_file < options_.exit_file_grace) return false;
  }
  append_to_log(job.slurm_output, job.job.log_file);
  const double seconds = std::chrono::duration<double>(Clock::now() - job.submitted).count();
  const std::string slurm = "Slurm job " + slurm_id + " (" + job.state + ")";
  if (status && *status <= 128) {
    results.push_back({job.job.id, *status == 0, *status == 0 ? "" : "exit code " + std::to_string(*status), seconds, false});
  } else if (is_deliberate_end(job.state)) {
    results.push_back({job.job.id, false, slurm + " ended it", seconds, false});
  } else if (status) {
    results.push_back(lost(job, slurm + ": its command was killed by signal " + std::to_string(*status - 128)));
  } else {
    results.push_back(lost(job, slurm + " ended without the command's exit status"));
  }
  return true;
}

JobResult SlurmExecutor::lost(const Submitted& job, const std::string& why) {
  const double seconds = std::chrono::duration<double>(Clock::now() - job.submitted).count();
  const int requeues = requeues_[job.job.id]++;
  if (requeues < options_.max_requeues) {
    return {job.job.id, false,
            why + "; submitting it again (requeue " + std::to_string(requeues + 1) + " of " +
                std::to_string(options_.max_requeues) + ")",
            seconds, true};
  }
  return {job.job.id, false, why + "; lost " + std::to_string(requeues + 1) + " times, not submitted again (--max-requeues " +
                                 std::to_string(options_.max_requeues) + ")",
          seconds, false};
}

std::vector<JobResult> SlurmExecutor::wait(std::chrono::milliseconds timeout) {
  std::vector<JobResult> results;
  const auto deadline = Clock::now() + timeout;
  submit_queued(results);
  while (results.empty() && !submitted_.empty()) {
    if (Clock::now() >= next_poll_) {
      poll(results);
      next_poll_ = Clock::now() + options_.poll_interval;
    }
    if (!results.empty() || Clock::now() >= deadline) break;
    std::this_thread::sleep_until(std::min(deadline, next_poll_));
  }
  return results;
}

void SlurmExecutor::cancel_all() {
  queue_.clear();
  if (submitted_.empty()) return;
  std::vector<std::string> args = {scancel_.string()};
  for (const auto& [slurm_id, job] : submitted_) args.push_back(slurm_id);
  if (const ProgramResult result = run_program(args); result.exit_code != 0)
    spdlog::warn("tega run: scancel failed: {}", last_line(result.output));
  const auto deadline = Clock::now() + options_.cancel_timeout;
  for (;;) {
    bool any_left = true;  // until squeue says otherwise
    if (const auto states = queue_states()) {
      any_left = false;
      for (const auto& [slurm_id, job] : submitted_) {
        const auto state = states->find(slurm_id);
        any_left = any_left || (state != states->end() && !is_final(state->second));
      }
    }
    if (!any_left) break;
    if (Clock::now() >= deadline) {
      spdlog::warn("tega run: Slurm still reports cancelled jobs unfinished after {} s", options_.cancel_timeout.count() / 1000);
      break;
    }
    std::this_thread::sleep_for(std::min(options_.poll_interval, std::chrono::milliseconds(500)));
  }
  for (const auto& [slurm_id, job] : submitted_) {
    append_to_log(job.slurm_output, job.job.log_file);
    fs::remove(slurm_job_files(job.job.log_file).record);
  }
  submitted_.clear();
}

std::vector<std::string> SlurmExecutor::running() const {
  std::vector<std::string> ids;
  for (const auto& [slurm_id, job] : submitted_) {
    if (job.state == "RUNNING") ids.push_back(job.job.id);
  }
  return ids;
}

}  // namespace tega::pipeline
