#include "tega/pipeline/local_executor.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

#include <algorithm>
#include <cstring>
#include <string_view>
#include <string>
#include <thread>

#include "tega/core/error.h"
#include "tega/core/thread_pool.h"
#include "tega/pipeline/manifest.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr auto kPollInterval = std::chrono::milliseconds(20);

// A job of several GPUs holds them alone.
int jobs_sharing_a_gpu(const Resources& resources) {
  return resources.gpu_count > 1 ? 1 : std::max(1, resources.jobs_per_gpu);
}

std::string describe_exit(int status) {
  if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
                                  strsignal(WTERMSIG(status)) + ")";
  return "ended with wait status " + std::to_string(status);
}

// This process's environment with CUDA_VISIBLE_DEVICES set to `gpu` ("" leaves it as it is) and
// the job's threads in TEGA_THREADS and OMP_NUM_THREADS.
std::vector<std::string> child_environment(const std::string& gpu, int threads) {
  static constexpr std::string_view kVisible = "CUDA_VISIBLE_DEVICES=", kThreads = "TEGA_THREADS=",
                                    kOpenMp = "OMP_NUM_THREADS=";
  const auto is = [](std::string_view entry, std::string_view name) { return entry.substr(0, name.size()) == name; };
  std::vector<std::string> environment;
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const bool replaced = (!gpu.empty() && is(*entry, kVisible)) || is(*entry, kThreads) || is(*entry, kOpenMp);
    if (!replaced) environment.push_back(*entry);
  }
  if (!gpu.empty()) environment.push_back(std::string(kVisible) + gpu);
  environment.push_back(std::string(kThreads) + std::to_string(threads));
  environment.push_back(std::string(kOpenMp) + std::to_string(threads));
  return environment;
}

std::vector<char*> null_terminated(const std::vector<std::string>& strings) {
  std::vector<char*> pointers;
  for (const auto& s : strings) pointers.push_back(const_cast<char*>(s.c_str()));
  pointers.push_back(nullptr);
  return pointers;
}

// Between fork and exec only async-signal-safe calls are allowed.
[[noreturn]] void exec_child(pid_t parent, int log_fd, const char* directory, char* const* argv, char* const* envp) {
  ::setpgid(0, 0);  // its own group: a terminal's Ctrl-C reaches the orchestrator, which stops the jobs
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(125);  // the orchestrator died before prctl took effect
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  const int null_fd = ::open("/dev/null", O_RDONLY);
  if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
  ::dup2(log_fd, STDOUT_FILENO);
  ::dup2(log_fd, STDERR_FILENO);
  if (::chdir(directory) != 0) {
    const char message[] = "tega run: cannot enter the working directory\n";
    (void)!::write(STDERR_FILENO, message, sizeof message - 1);
    ::_exit(126);
  }
  ::execve(argv[0], argv, envp);
  const char message[] = "tega run: cannot execute the shard's command\n";
  (void)!::write(STDERR_FILENO, message, sizeof message - 1);
  ::_exit(127);
}

}  // namespace

LocalExecutor::LocalExecutor(int cpu_slots, std::vector<std::string> gpus, std::chrono::milliseconds stop_grace,
                             int cores)
    : cpu_slots_(std::max(1, cpu_slots)), cores_(cores > 0 ? cores : default_thread_count()), gpus_(std::move(gpus)),
      stop_grace_(stop_grace) {}

LocalExecutor::~LocalExecutor() { cancel_all(); }

void LocalExecutor::submit(Job job) { queue_.push_back(std::move(job)); }

pid_t LocalExecutor::launch(const Job& job, const std::string& pinned, int threads) {
  fs::create_directories(job.log_file.parent_path());
  const int log_fd = ::open(job.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw Error(job.log_file, "cannot be opened for writing");
  const std::string on = pinned.empty() ? "" : (pinned.find(',') == std::string::npos ? " on GPU " : " on GPUs ") + pinned;
  std::string header = "=== " + utc_now() + " " + job.id + on + ", " + std::to_string(threads) +
                       (threads == 1 ? " thread:" : " threads:");
  for (const auto& a : job.argv) header += " " + a;
  header += "\n";
  (void)!::write(log_fd, header.data(), header.size());

  // Built before fork: between fork and exec nothing may allocate.
  std::vector<char*> argv = null_terminated(job.argv);
  const std::vector<std::string> environment = child_environment(pinned, threads);
  std::vector<char*> envp = null_terminated(environment);
  const std::string directory = job.working_directory.string();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) exec_child(parent, log_fd, directory.c_str(), argv.data(), envp.data());
  ::close(log_fd);
  if (pid < 0) throw Error(std::string("cannot start ") + job.id + ": fork failed: " + std::strerror(errno));
  ::setpgid(pid, pid);  // also here, so that the group exists before any kill(-pid)
  return pid;
}

std::optional<LocalExecutor::Held> LocalExecutor::free_gpus(const Job& job, const std::vector<Running>& starting) const {
  // The jobs on `gpu` now (running or starting in this pass), or nullopt when `job` may not join
  // them: a GPU runs at most as many jobs as the strictest of their jobs_per_gpu and the job's own allow.
  const auto jobs_beside = [&](const std::string& gpu) -> std::optional<int> {
    int jobs = 0, bound = jobs_sharing_a_gpu(job.resources);
    const auto count = [&](const Running& r) {
      if (std::find(r.held.gpus.begin(), r.held.gpus.end(), gpu) == r.held.gpus.end()) return;
      ++jobs;
      bound = std::min(bound, jobs_sharing_a_gpu(r.job.resources));
    };
    for (const auto& [pid, r] : running_) count(r);
    for (const Running& r : starting) count(r);
    if (jobs >= bound) return std::nullopt;
    return jobs;
  };
  const std::string& device = job.resources.gpu_device;
  if (device == "cuda" && !gpus_.empty()) {
    const size_t wanted = size_t(std::max(1, job.resources.gpu_count));
    // The least busy GPUs first, so that shared ones fill only when none is idle.
    std::vector<std::pair<int, size_t>> open;  // (jobs on it, index in gpus_)
    for (size_t i = 0; i < gpus_.size(); ++i)
      if (const auto jobs = jobs_beside(gpus_[i])) open.emplace_back(*jobs, i);
    if (open.size() < wanted) return std::nullopt;
    std::stable_sort(open.begin(), open.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    Held free{{}, true};
    for (size_t k = 0; k < wanted; ++k) free.gpus.push_back(gpus_[open[k].second]);
    return free;
  }
  const std::string gpu = device.rfind("cuda:", 0) == 0 ? device.substr(5) : device;
  if (!jobs_beside(gpu)) return std::nullopt;
  return Held{{gpu}, false};
}

void LocalExecutor::start_ready_jobs(std::vector<JobResult>& results) {
  int cpu_running = 0;
  for (const auto& [pid, r] : running_) cpu_running += r.held.gpus.empty() ? 1 : 0;
  // First which jobs start, then their share of the cores among all that will be running.
  std::vector<Running> starting;
  std::deque<Job> waiting;
  // Jobs for any of the run's GPUs start in queue order: a job waiting for several GPUs is not
  // starved by later ones that each take one as it frees.
  bool pooled_waiting = false;
  for (Job& job : queue_) {
    const bool cpu_job = job.resources.gpu_device.empty();
    const bool pooled = job.resources.gpu_device == "cuda" && !gpus_.empty();
    if (!cpu_job && !gpus_.empty() && job.resources.gpu_count > int(gpus_.size())) {
      results.push_back({job.id, false,
                         "could not start: it needs " + std::to_string(job.resources.gpu_count) +
                             " GPUs at once and this run has " + std::to_string(gpus_.size()) + " (tega run --gpus)",
                         0});
      continue;
    }
    std::optional<Held> gpus;
    if (cpu_job ? cpu_running >= cpu_slots_ : (pooled && pooled_waiting) || !(gpus = free_gpus(job, starting))) {
      pooled_waiting = pooled_waiting || pooled;
      waiting.push_back(std::move(job));
      continue;
    }
    starting.push_back({std::move(job), cpu_job ? Held{} : *gpus, {}});
    cpu_running += cpu_job ? 1 : 0;
  }
  queue_ = std::move(waiting);
  const int threads = std::max(1, cores_ / std::max<int>(1, int(running_.size() + starting.size())));
  for (Running& s : starting) {
    try {
      std::string pinned;
      if (s.held.pinned)
        for (const std::string& gpu : s.held.gpus) pinned += (pinned.empty() ? "" : ",") + gpu;
      const pid_t pid = launch(s.job, pinned, threads);
      s.started = Clock::now();
      running_[pid] = std::move(s);
    } catch (const std::exception& e) {
      results.push_back({s.job.id, false, std::string("could not start: ") + e.what(), 0});
    }
  }
}

bool LocalExecutor::reap(std::vector<JobResult>& results, bool block) {
  bool any = false;
  for (auto it = running_.begin(); it != running_.end();) {
    int status = 0;
    struct rusage usage {};
    const pid_t done = ::wait4(it->first, &status, block ? 0 : WNOHANG, &usage);
    if (done == it->first || (done < 0 && errno == ECHILD)) {
      const double seconds = std::chrono::duration<double>(Clock::now() - it->second.started).count();
      const bool ok = done == it->first && WIFEXITED(status) && WEXITSTATUS(status) == 0;
      JobResult result{it->second.job.id, ok, ok ? "" : done < 0 ? "lost track of the process" : describe_exit(status),
                       seconds};
      if (done == it->first) result.peak_rss_kib = usage.ru_maxrss;  // Linux: kibibytes
      results.push_back(std::move(result));
      it = running_.erase(it);
      any = true;
    } else {
      ++it;
    }
  }
  return any;
}

std::vector<JobResult> LocalExecutor::wait(std::chrono::milliseconds timeout) {
  std::vector<JobResult> results;
  const auto deadline = Clock::now() + timeout;
  start_ready_jobs(results);
  while (results.empty() && Clock::now() < deadline && !running_.empty()) {
    std::this_thread::sleep_for(kPollInterval);
    if (reap(results, false)) start_ready_jobs(results);
  }
  return results;
}

void LocalExecutor::cancel_all() {
  queue_.clear();
  for (const auto& [pid, r] : running_) ::kill(-pid, SIGTERM);
  const auto deadline = Clock::now() + stop_grace_;
  std::vector<JobResult> ignored;
  while (!running_.empty() && Clock::now() < deadline) {
    reap(ignored, false);
    if (!running_.empty()) std::this_thread::sleep_for(kPollInterval);
  }
  for (const auto& [pid, r] : running_) ::kill(-pid, SIGKILL);
  reap(ignored, true);
}

std::vector<std::string> LocalExecutor::running() const {
  std::vector<std::string> ids;
  for (const auto& [pid, r] : running_) ids.push_back(r.job.id);
  return ids;
}

}  // namespace tega::pipeline
