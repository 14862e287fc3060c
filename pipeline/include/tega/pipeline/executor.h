#pragma once
// Executors run shard commands; the orchestrator decides what runs and
// commits the results. A job is a command line, a log file and the resources
// it needs, so a cluster executor (SlurmExecutor: Slurm batch jobs and job
// arrays, polled through squeue) runs the very same jobs without any stage
// changing.

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

namespace tega::pipeline {

struct Resources {
  // "" for a CPU job; else the GPU device it uses. "cuda": any one GPU, which the executor
  // chooses (the local one pins the job to it with CUDA_VISIBLE_DEVICES); "cuda:1": that
  // device, as the machine numbers it. A GPU runs one job at a time unless jobs_per_gpu says more.
  std::string gpu_device;
  // GPUs a "cuda" job holds at once (a train shard of `gpus_per_job: N`): the local executor pins
  // it to that many free GPUs (CUDA_VISIBLE_DEVICES=a,b,...), Slurm asks for them (--gres=gpu:N).
  int gpu_count = 1;
  // Jobs one GPU runs at once while this job is among them (the local executor; each job's own
  // bound holds, and a job of several GPUs holds them alone). A stage's `jobs_per_gpu`: for jobs
  // that leave their GPU idle much of the time, as mvs's do while they build surfaces on the CPU.
  // Slurm gives every job GPUs of its own.
  int jobs_per_gpu = 1;
};

struct Job {
  std::string id;                  // "<stage>/<shard>", unique among an executor's jobs
  std::vector<std::string> argv;   // argv[0] is the program
  std::filesystem::path working_directory;
  std::filesystem::path log_file;  // stdout and stderr, appended
  Resources resources;
};

struct JobResult {
  std::string id;
  bool succeeded = false;
  std::string failure;  // "exit code 1", "killed by signal 9", "could not start: ..."
  double seconds = 0;
  // The job was lost to its cluster (node failure, preemption, its process killed), not failed by
  // its command, and may be tried again: the orchestrator prepares its shard afresh (a killed
  // attempt leaves a partial staging directory) and submits it again under the same id.
  bool requeue = false;
  // The largest resident memory of the job's process (or, of its children, the largest one's),
  // kibibytes; 0 where the executor cannot tell (Slurm).
  long peak_rss_kib = 0;
};

class Executor {
 public:
  virtual ~Executor() = default;

  // Queues a job; it starts when its resources are free. Never blocks.
  virtual void submit(Job job) = 0;

  // Waits at most `timeout` for jobs to finish and returns those that did
  // (possibly none), each exactly once.
  virtual std::vector<JobResult> wait(std::chrono::milliseconds timeout) = 0;

  // Drops queued jobs and stops running ones; returns when none runs any more.
  // Their results are not reported.
  virtual void cancel_all() = 0;

  virtual std::vector<std::string> running() const = 0;  // ids of the jobs running now
  virtual size_t unfinished() const = 0;                  // queued or running
};

}  // namespace tega::pipeline
