#pragma once
// Runs jobs as child processes of this one: up to `cpu_slots` CPU jobs at
// once, and one job at a time per GPU, or up to the jobs' jobs_per_gpu
// (Resources). A job for "cuda" runs on the least busy GPU of `gpus` that has
// room, pinned to it with CUDA_VISIBLE_DEVICES (so it sees that GPU alone, as
// its device 0); one of gpu_count N > 1 waits for N free GPUs
// and is pinned to all of them (its devices 0 to N-1). Such jobs start in
// queue order: a later one never takes a GPU that an earlier one waits for.
// With no `gpus` they run unpinned, one at a time (or jobs_per_gpu). A job for
// "cuda:N" runs on device N, unpinned, when N has room. Children die with the
// orchestrator (PR_SET_PDEATHSIG), even when it is killed with SIGKILL, so no
// orphan keeps writing into a workspace that a new run is cleaning up.
//
// Children are forked from the thread that constructs the executor and calls
// wait(); the death signal follows that thread, so it must outlive the jobs.

#include <chrono>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <sys/types.h>

#include "tega/pipeline/executor.h"

namespace tega::pipeline {

class LocalExecutor : public Executor {
 public:
  // `gpus`: CUDA_VISIBLE_DEVICES entries (gpus.h), e.g. machine_gpus().
  explicit LocalExecutor(int cpu_slots, std::vector<std::string> gpus = {},
                         std::chrono::milliseconds stop_grace = std::chrono::seconds(5));
  ~LocalExecutor() override;  // cancel_all()

  void submit(Job job) override;
  std::vector<JobResult> wait(std::chrono::milliseconds timeout) override;
  // SIGTERM to every running job, SIGKILL to those still alive after the grace period.
  void cancel_all() override;
  std::vector<std::string> running() const override;
  size_t unfinished() const override { return queue_.size() + running_.size(); }

 private:
  // The GPUs a job holds: `gpus` entries, "N" of "cuda:N", or "cuda"; none for a CPU job.
  struct Held {
    std::vector<std::string> gpus;
    bool pinned = false;  // started with CUDA_VISIBLE_DEVICES naming them
  };
  struct Running {
    Job job;
    Held held;
    std::chrono::steady_clock::time_point started;
  };

  void start_ready_jobs(std::vector<JobResult>& results);
  // The GPUs `job` can start on now; nullopt while it must wait.
  std::optional<Held> free_gpus(const Job& job) const;
  // Throws tega::Error when the log cannot be opened or fork fails. `pinned`: "a,b" or "".
  pid_t launch(const Job& job, const std::string& pinned);
  bool reap(std::vector<JobResult>& results, bool block);

  int cpu_slots_;
  std::vector<std::string> gpus_;
  std::chrono::milliseconds stop_grace_;
  std::deque<Job> queue_;
  std::map<pid_t, Running> running_;
};

}  // namespace tega::pipeline
