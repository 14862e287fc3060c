#pragma once
// The files SlurmExecutor keeps next to a job's log (logs/<stage>/<shard>.*):
//
//   <shard>.slurm.sh    the batch script: runs the job's command in its working directory, its
//                       output appended to the log, then writes the command's exit status
//   <shard>.slurm-exit  that exit status, written atomically (tmp + mv) when the command ends; a job
//                       that Slurm reports ended without it was lost (node failure, preemption, the
//                       script killed), not failed by its command
//   <shard>.slurm.json  the Slurm job id and state while the job is queued or running, so that
//                       `tega status` can show them without asking Slurm; an array task's id is
//                       "<array>_<task>", as squeue names it
//
// Shards of one stage submitted together go out as one job array, with two files in the first
// shard's log directory:
//
//   slurm-array.sh        the array's batch script: task i runs the i-th shard's <shard>.slurm.sh,
//                         its output appended to that shard's log; the next array rewrites it
//   slurm-<array>_<task>.out  Slurm's own messages for one task (a time limit, a script that could
//                         not start), appended to the shard's log when the task ends

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tega/pipeline/executor.h"

namespace tega::pipeline {

// `word` in single quotes, each ' as '\'': a POSIX shell reads it back unchanged, whatever it holds.
std::string shell_quote(const std::string& word);

struct SlurmJobFiles {
  std::filesystem::path script, exit_file, record;
};
SlurmJobFiles slurm_job_files(const std::filesystem::path& log_file);

// The batch script of `job`. Every value from the job is shell-quoted; the log's first line per
// attempt is "=== <time> <id>: <command> [slurm job <id> on <node>]", as LocalExecutor's header.
std::string batch_script(const Job& job, const std::filesystem::path& exit_file);

// The batch script of a job array of `jobs`, whose shard scripts (batch_script) are already written:
// task i (SLURM_ARRAY_TASK_ID) runs jobs[i]'s. Every path is shell-quoted.
std::string array_batch_script(const std::vector<Job>& jobs);

struct SlurmJobRecord {
  std::string job_id;
  std::string state;  // as squeue names it: PENDING, RUNNING, ...
};
void write_slurm_job_record(const std::filesystem::path& file, const SlurmJobRecord& record);
std::optional<SlurmJobRecord> read_slurm_job_record(const std::filesystem::path& file);  // nullopt when absent or unreadable

}  // namespace tega::pipeline
