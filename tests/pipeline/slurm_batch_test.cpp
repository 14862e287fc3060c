// The batch script SlurmExecutor submits, run here by /bin/sh without Slurm: whatever a job's
// strings hold reaches the command unchanged, and the exit file records how the command ended.

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
