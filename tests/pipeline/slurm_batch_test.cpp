// The batch scripts SlurmExecutor submits, run here by /bin/sh without Slurm: whatever a job's
// strings hold reaches the command unchanged, the exit file records how the command ended, and an
// array task runs its own shard's script into its own log.

#include "tega/pipeline/slurm_batch.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>

#include "tega/core/files.h"
#include "test_support.h"

namespace tega::pipeline {
namespace {

TEST(SlurmBatch, ShellQuoteSurvivesQuotes) {
  EXPECT_EQ(shell_quote("plain"), "'plain'");
  EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
  EXPECT_EQ(shell_quote(""), "''");
}

TEST(SlurmBatch, ScriptPassesEveryArgumentUnchangedAndRecordsTheExitStatus) {
  test::TempDir dir;
  std::filesystem::create_directories(dir / "work dir's");
  std::filesystem::create_directories(dir / "logs");
  Job job;
  job.id = "stage/shard";
  const std::vector<std::string> nasty = {"it's", "$HOME", "a  b", "`touch pwned`", "line\nbreak", "*", "; exit 9"};
  job.argv = {"/bin/sh", "-c", "pwd > where.txt; printf '%s\\n' \"$@\" > args.txt; exit 3", "sh"};
  job.argv.insert(job.argv.end(), nasty.begin(), nasty.end());
  job.working_directory = dir / "work dir's";
  job.log_file = dir / "logs/shard.log";
  const SlurmJobFiles files = slurm_job_files(job.log_file);
  EXPECT_EQ(files.script, dir / "logs/shard.slurm.sh");
  EXPECT_EQ(files.exit_file, dir / "logs/shard.slurm-exit");

  test::write_text(files.script, batch_script(job, files.exit_file));
  const int status = std::system(("/bin/sh " + shell_quote(files.script.string()) + " > " +
                                  shell_quote(job.log_file.string()) + " 2>&1")
                                     .c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3);
  EXPECT_EQ(read_text_file(files.exit_file), "3\n");
  std::string expected_args;
  for (const auto& a : nasty) expected_args += a + "\n";
  EXPECT_EQ(read_text_file(job.working_directory / "args.txt"), expected_args);
  EXPECT_EQ(read_text_file(job.working_directory / "where.txt"), job.working_directory.string() + "\n");
  EXPECT_FALSE(std::filesystem::exists(job.working_directory / "pwned"));
  EXPECT_EQ(read_text_file(job.log_file).rfind("=== ", 0), 0u) << read_text_file(job.log_file);
}

// A shard whose command prints its arguments; its paths hold a quote and a space.
Job printing_job(const std::filesystem::path& dir, const std::string& shard, const std::string& argument) {
  Job job;
  job.id = "stage/" + shard;
  job.argv = {"/bin/sh", "-c", "printf '%s\\n' \"$@\"", "sh", argument};
  job.working_directory = dir;
  job.log_file = dir / "logs it's" / (shard + ".log");
  std::filesystem::create_directories(job.log_file.parent_path());
  test::write_text(slurm_job_files(job.log_file).script, batch_script(job, slurm_job_files(job.log_file).exit_file));
  return job;
}

int run_array_task(const std::filesystem::path& script, const std::string& task) {
  return std::system(("SLURM_ARRAY_JOB_ID=77 SLURM_ARRAY_TASK_ID=" + task + " /bin/sh " +
                      shell_quote(script.string()) + " >/dev/null 2>&1")
                         .c_str());
}

TEST(SlurmBatch, ArrayTaskRunsItsOwnShardIntoItsOwnLog) {
  test::TempDir dir;
  const std::vector<Job> jobs = {printing_job(dir.path(), "alice", "$HOME 'a'"),
                                 printing_job(dir.path(), "bob's", "`touch pwned`")};
  const std::filesystem::path script = dir / "array.sh";
  test::write_text(script, array_batch_script(jobs));

  const int status = run_array_task(script, "1");
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(read_text_file(slurm_job_files(jobs[1].log_file).exit_file), "0\n");
  const std::string log = read_text_file(jobs[1].log_file);
  EXPECT_EQ(log.rfind("=== ", 0), 0u) << log;
  EXPECT_NE(log.find("[slurm job 77_1 on "), std::string::npos) << log;
  EXPECT_NE(log.find("\n`touch pwned`\n"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "pwned"));
  EXPECT_FALSE(std::filesystem::exists(jobs[0].log_file));
  EXPECT_FALSE(std::filesystem::exists(slurm_job_files(jobs[0].log_file).exit_file));

  ASSERT_EQ(run_array_task(script, "0"), 0);
  EXPECT_NE(read_text_file(jobs[0].log_file).find("\n$HOME 'a'\n"), std::string::npos);
}

TEST(SlurmBatch, ArrayTaskWithoutAShardFailsWithoutAnExitFile) {
  test::TempDir dir;
  const std::vector<Job> jobs = {printing_job(dir.path(), "alice", "a"), printing_job(dir.path(), "bob", "b")};
  const std::filesystem::path script = dir / "array.sh";
  test::write_text(script, array_batch_script(jobs));
  for (const char* task : {"2", "1; touch pwned", ""}) {
    EXPECT_NE(run_array_task(script, shell_quote(task)), 0) << task;
  }
  for (const Job& job : jobs) EXPECT_FALSE(std::filesystem::exists(slurm_job_files(job.log_file).exit_file));
  EXPECT_FALSE(std::filesystem::exists(dir / "pwned"));
}

TEST(SlurmBatch, JobRecordRoundTrips) {
  test::TempDir dir;
  EXPECT_FALSE(read_slurm_job_record(dir / "none.slurm.json"));
  write_slurm_job_record(dir / "a.slurm.json", {"42", "RUNNING"});
  const auto record = read_slurm_job_record(dir / "a.slurm.json");
  ASSERT_TRUE(record);
  EXPECT_EQ(record->job_id, "42");
  EXPECT_EQ(record->state, "RUNNING");
}

}  // namespace
}  // namespace tega::pipeline
