// What SlurmExecutor asks Slurm for, through stand-in sbatch, squeue and scancel that record their
// arguments: no cluster needed (slurm_test.cpp runs real jobs on one).

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "tega/core/files.h"
#include "tega/pipeline/slurm_executor.h"
#include "test_support.h"

namespace tega::pipeline {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

void write_tool(const fs::path& file, const std::string& script) {
  write_text_atomic(file, "#!/bin/sh\n" + script + "\n");
  fs::permissions(file, fs::perms::owner_all, fs::perm_options::add);
}

Job gpu_job(const std::string& id, int gpus, const test::TempDir& dir) {
  Job job;
  job.id = id;
  job.argv = {"/bin/true"};
  job.working_directory = dir.path();
  job.log_file = dir / ("logs/" + id + ".log");
  job.resources.gpu_device = "cuda";
  job.resources.gpu_count = gpus;
  return job;
}

TEST(SlurmGpus, AJobOfFourGpusAsksForFourAndOthersForGpusPerJob) {
  test::TempDir dir;
  const fs::path bin = dir / "bin", calls = dir / "sbatch-calls";
  fs::create_directories(bin);
  write_tool(bin / "sbatch", "echo \"$*\" >> '" + calls.string() + "'; echo 4242");
  write_tool(bin / "squeue", "exit 0");  // knows no job: each is over (and, without an exit file, lost)
  write_tool(bin / "scancel", "exit 0");
  SlurmOptions options;
  options.bin_dir = bin;
  options.gpus_per_job = 2;
  options.max_requeues = 0;
  options.poll_interval = 10ms;
  options.exit_file_grace = 0ms;
  options.cancel_timeout = 100ms;
  {
    SlurmExecutor executor(options);
    executor.submit(gpu_job("train/alice", 4, dir));
    executor.submit(gpu_job("eval/alice", 1, dir));
    for (int i = 0; i < 20 && executor.unfinished() > 0; ++i) executor.wait(50ms);
  }
  std::istringstream lines(read_text_file(calls));
  int train = 0, eval = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("--job-name=tega:train/alice") != std::string::npos) {
      ++train;
      EXPECT_NE(line.find("--gres=gpu:4"), std::string::npos) << line;
    }
    if (line.find("--job-name=tega:eval/alice") != std::string::npos) {
      ++eval;
      EXPECT_NE(line.find("--gres=gpu:2"), std::string::npos) << line;  // --gpus-per-job, the larger
    }
  }
  EXPECT_EQ(train, 1);
  EXPECT_EQ(eval, 1);
}

}  // namespace
}  // namespace tega::pipeline
