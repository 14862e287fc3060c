#pragma once
// Runs jobs as child processes of this one: up to `cpu_slots` CPU jobs at
// once, and one job at a time per GPU device. Children die with the
// orchestrator (PR_SET_PDEATHSIG), even when it is killed with SIGKILL, so no
// orphan keeps writing into a workspace that a new run is cleaning up.
//
// Children are forked from the thread that constructs the executor and calls
// wait(); the death signal follows that thread, so it must outlive the jobs.

#include <chrono>
#include <deque>
#include <map>
#include <sys/types.h>

#include "tega/pipeline/executor.h"

namespace tega::pipeline {

class LocalExecutor : public Executor {
 public:
  explicit LocalExecutor(int cpu_slots, std::chrono::milliseconds stop_grace = std::chrono::seconds(5));
  ~LocalExecutor() override;  // cancel_all()

  void submit(Job job) override;
  std::vector<JobResult> wait(std::chrono::milliseconds timeout) override;
  // SIGTERM to every running job, SIGKILL to those still alive after the grace period.
  void cancel_all() override;
  std::vector<std::string> running() const override;
  size_t unfinished() const override { return queue_.size() + running_.size(); }

 private:
  struct Running {
    Job job;
    std::chrono::steady_clock::time_point started;
  };

  void start_ready_jobs(std::vector<JobResult>& results);
  pid_t launch(const Job& job);  // throws tega::Error when the log cannot be opened or fork fails
  bool reap(std::vector<JobResult>& results, bool block);

  int cpu_slots_;
  std::chrono::milliseconds stop_grace_;
  std::deque<Job> queue_;
  std::map<pid_t, Running> running_;
};

}  // namespace tega::pipeline
