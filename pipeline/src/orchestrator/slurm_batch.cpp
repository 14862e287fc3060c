#include "tega/pipeline/slurm_batch.h"

#include <nlohmann/json.hpp>

#include "tega/core/files.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

std::string shell_quote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

SlurmJobFiles slurm_job_files(const fs::path& log_file) {
  auto beside = [&](const char* extension) { return fs::path(log_file).replace_extension(extension); };
  return {beside(".slurm.sh"), beside(".slurm-exit"), beside(".slurm.json")};
}

std::string batch_script(const Job& job, const fs::path& exit_file) {
  std::string command, quoted_command;
  for (const auto& a : job.argv) {
    if (!command.empty()) {
      command += ' ';
      quoted_command += ' ';
    }
    command += a;
    quoted_command += shell_quote(a);
  }
  // No `exec`: the shell must outlive the command to record how it ended. A command killed by a
  // signal leaves status 128+N, which SlurmExecutor treats as lost rather than failed.
  return "#!/bin/sh\n"
         "# Written by `tega run` (SlurmExecutor) for one shard; every attempt rewrites it.\n"
         "exit_file=" + shell_quote(exit_file.string()) + "\n"
         "# An array task goes by <array>_<task>, as squeue and `tega status` name it.\n"
         "slurm_job=${SLURM_ARRAY_JOB_ID:+${SLURM_ARRAY_JOB_ID}_$SLURM_ARRAY_TASK_ID}\n"
         "printf '=== %s %s: %s [slurm job %s on %s]\\n' \"$(date -u +%Y-%m-%dT%H:%M:%SZ)\" " +
         shell_quote(job.id) + " " + shell_quote(command) + " \"${slurm_job:-$SLURM_JOB_ID}\" \"$(hostname)\"\n"
         "cd " + shell_quote(job.working_directory.string()) + " && " + quoted_command + " </dev/null\n"
         "status=$?\n"
         "echo \"$status\" > \"$exit_file.tmp\" && mv -f \"$exit_file.tmp\" \"$exit_file\"\n"
         "exit \"$status\"\n";
}

std::string array_batch_script(const std::vector<Job>& jobs) {
  std::string tasks;
  for (size_t i = 0; i < jobs.size(); ++i) {
    tasks += "  " + std::to_string(i) + ") script=" + shell_quote(slurm_job_files(jobs[i].log_file).script.string()) +
             " log=" + shell_quote(jobs[i].log_file.string()) + " ;;\n";
  }
  // exec: the shard's script is the task's process, so that Slurm's signals reach it directly.
  return "#!/bin/sh\n"
         "# Written by `tega run` (SlurmExecutor) for a job array of " + std::to_string(jobs.size()) +
         " shards; each task runs its shard's script.\n"
         "case \"$SLURM_ARRAY_TASK_ID\" in\n" + tasks +
         "  *) echo \"no shard for array task '$SLURM_ARRAY_TASK_ID'\" >&2; exit 1 ;;\n"
         "esac\n"
         "exec /bin/sh \"$script\" >> \"$log\" 2>&1\n";
}

void write_slurm_job_record(const fs::path& file, const SlurmJobRecord& record) {
  const json j = {{"job_id", record.job_id}, {"state", record.state}};
  write_text_atomic(file, j.dump(2) + "\n");
}

std::optional<SlurmJobRecord> read_slurm_job_record(const fs::path& file) {
  if (!fs::exists(file)) return std::nullopt;
  try {
    const json j = json::parse(read_text_file(file));
    return SlurmJobRecord{j.at("job_id"), j.at("state")};
  } catch (const std::exception&) {
    return std::nullopt;  // removed or replaced while being read: the shard is ending
  }
}

}  // namespace tega::pipeline
