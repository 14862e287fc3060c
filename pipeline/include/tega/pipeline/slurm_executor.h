#pragma once
// Runs every job as a Slurm batch job (`tega run --executor slurm`, docs/pipeline.md#running-on-a-slurm-cluster).
//
// submit() only queues; wait() calls sbatch for queued jobs and polls squeue. Queued jobs of one stage
// (the id's part before '/') that ask for the same resources go out as one job array, a task per
// job, known by its "<array>_<task>" id from then on (squeue -r, scancel, the status record); a
// job alone in its group is a plain job. A job is over when
// squeue reports a final state or no longer knows it. How it ended comes from the exit file its
// batch script writes (slurm_batch.h), not from sacct: that needs accounting storage, which many
// small clusters (and the test's one-node cluster) do not run, and the file says what the command
// itself did. A job lost to the cluster (no exit file, or its command killed by a signal: node
// failure, preemption, a killed process) is reported with `requeue` set, up to `max_requeues`
// times, so that the orchestrator prepares its shard afresh and submits it again; a command that
// exits non-zero failed, as with LocalExecutor.
//
// The workspace, the config's directory and the tega binary must be on storage that the compute
// nodes share with this host, at the same paths. Jobs outlive a `tega run` killed with SIGKILL
// (nothing kills them with it, unlike LocalExecutor's children): scancel them before running again.

#include <chrono>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tega/pipeline/executor.h"

namespace tega::pipeline {

struct SlurmOptions {
  // sbatch --partition; empty: the cluster's default partition.
  std::string partition;
  // GPUs a GPU job (one whose Resources name a device) asks for: sbatch --gres=gpu:N, or the job's
  // Resources::gpu_count when larger. Inside the job
  // Slurm's CUDA_VISIBLE_DEVICES numbers them from 0, so a stage's `device: cuda:K` names the job's
  // K-th GPU; K >= gpus_per_job is refused at submission.
  int gpus_per_job = 1;
  // How many times a lost job is submitted again before its shard fails.
  int max_requeues = 2;
  // How often squeue is asked about the jobs.
  std::chrono::milliseconds poll_interval = std::chrono::seconds(3);
  // How long a job that Slurm reports over may take to show its exit file here (shared storage
  // can show a file on this host a little after a node wrote it) before it counts as lost.
  std::chrono::milliseconds exit_file_grace = std::chrono::seconds(10);
  // How long cancel_all() waits for cancelled jobs to leave the queue.
  std::chrono::milliseconds cancel_timeout = std::chrono::seconds(60);
  // Where sbatch, squeue and scancel are; empty: found on PATH.
  std::filesystem::path bin_dir;
  // Jobs are named this prefix + the job id ("tega:synth/alice"), for squeue and scancel --name.
  std::string job_name_prefix = "tega:";
};

class SlurmExecutor : public Executor {
 public:
  // Throws tega::Error when sbatch, squeue or scancel cannot be found.
  explicit SlurmExecutor(SlurmOptions options);
  ~SlurmExecutor() override;  // cancel_all()

  void submit(Job job) override;
  std::vector<JobResult> wait(std::chrono::milliseconds timeout) override;
  // scancel for every submitted job; returns once Slurm reports them over (or after cancel_timeout).
  void cancel_all() override;
  std::vector<std::string> running() const override;  // those squeue last reported RUNNING
  size_t unfinished() const override { return queue_.size() + submitted_.size(); }

 private:
  struct Submitted {
    Job job;
    std::string state;  // squeue's, from the last poll
    std::chrono::steady_clock::time_point submitted;
    std::optional<std::chrono::steady_clock::time_point> over_without_exit_file;
    std::filesystem::path slurm_output;  // an array task's own Slurm output (slurm_batch.h); else empty
  };

  void submit_queued(std::vector<JobResult>& results);
  void prepare(const Job& job) const;  // checks the job and writes its batch script; throws tega::Error
  std::vector<std::string> sbatch_arguments(const std::string& name, const std::string& output,
                                            const Resources& resources) const;
  std::string sbatch_job(const Job& job) const;  // the Slurm job id; throws tega::Error
  std::string sbatch_array(const std::vector<Job>& jobs) const;  // the array's Slurm job id; throws tega::Error
  void submit_group(std::vector<Job>& group);  // one plain job or one array; throws tega::Error
  void track(Job job, const std::string& slurm_id, std::filesystem::path slurm_output = {});
  // Slurm job id -> state, for those squeue still knows; nullopt when squeue could not be asked.
  std::optional<std::map<std::string, std::string>> queue_states() const;
  void poll(std::vector<JobResult>& results);
  // Whether the job's result is known yet (it is then added to `results`).
  bool conclude(Submitted& job, const std::string& slurm_id, std::vector<JobResult>& results);
  JobResult lost(const Submitted& job, const std::string& why);

  SlurmOptions options_;
  std::filesystem::path sbatch_, squeue_, scancel_;
  std::deque<Job> queue_;
  std::map<std::string, Submitted> submitted_;  // by Slurm job id, "<array>_<task>" for an array task
  std::map<std::string, int> requeues_;         // by job id
  std::chrono::steady_clock::time_point next_poll_;
};

}  // namespace tega::pipeline
