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
// The jobs share the machine's cores: each starts with TEGA_THREADS and
// OMP_NUM_THREADS set to `cores` over the jobs running once it has started
// (at least 1), which a stage's `threads: 0` takes (default_thread_count()),
// so that sixteen track jobs on sixteen cores do not run sixteen threads each.
// Its log's header line says how many.
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
  // `gpus`: CUDA_VISIBLE_DEVICES entries (gpus.h), e.g. machine_gpus(). `cores`: the threads the
  // jobs share (0: default_thread_count(), the machine's or the orchestrator's TEGA_THREADS).
  explicit LocalExecutor(int cpu_slots, std::vector<std::string> gpus = {},
                         std::chrono::milliseconds stop_grace = std::chrono::seconds(5), int cores = 0);
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
  // The GPUs `job` can start on now, beside the running jobs and those `starting` (not yet
  // launched); nullopt while it must wait.
  std::optional<Held> free_gpus(const Job& job, const std::vector<Running>& starting) const;
  // Throws tega::Error when the log cannot be opened or fork fails. `pinned`: "a,b" or "".
  pid_t launch(const Job& job, const std::string& pinned, int threads);
  bool reap(std::vector<JobResult>& results, bool block);

  int cpu_slots_;
  int cores_;
  std::vector<std::string> gpus_;
  std::chrono::milliseconds stop_grace_;
  std::deque<Job> queue_;
  std::map<pid_t, Running> running_;
};

}  // namespace tega::pipeline
