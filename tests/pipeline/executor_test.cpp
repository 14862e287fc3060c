#include "tega/pipeline/local_executor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <optional>

#include "tega/core/files.h"
#include "test_support.h"

namespace tega::pipeline {
namespace {

using namespace std::chrono_literals;

Job shell_job(const std::string& id, const std::string& script, const test::TempDir& dir, const std::string& gpu = "") {
  Job job;
  job.id = id;
  job.argv = {"/bin/sh", "-c", script};
  job.working_directory = dir.path();
  job.log_file = dir / ("logs/" + id + ".log");
  job.resources.gpu_device = gpu;
  return job;
}

std::vector<JobResult> wait_for_all(Executor& executor, std::chrono::seconds timeout) {
  std::vector<JobResult> results;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (executor.unfinished() > 0 && std::chrono::steady_clock::now() < deadline) {
    for (auto& r : executor.wait(100ms)) results.push_back(r);
  }
  return results;
}

// A job that fails if another job holding the same directory "lock" runs at the same time.
std::string exclusive(const std::string& lock) { return "mkdir " + lock + " || exit 3; sleep 0.2; rmdir " + lock; }

// Two jobs that each wait for the other to have started: they only succeed when run together.
std::string rendezvous(const std::string& mine, const std::string& other) {
  return "touch " + mine + "; i=0; while [ ! -e " + other + " ]; do i=$((i+1)); [ $i -gt 300 ] && exit 4; sleep 0.01; done";
}

TEST(LocalExecutor, RunsCpuJobsInParallelUpToItsSlots) {
  test::TempDir dir;
  LocalExecutor executor(2);
  executor.submit(shell_job("a", rendezvous("a.started", "b.started"), dir));
  executor.submit(shell_job("b", rendezvous("b.started", "a.started"), dir));
  const auto results = wait_for_all(executor, 20s);
  ASSERT_EQ(results.size(), 2u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
}

TEST(LocalExecutor, RunsOneCpuJobAtATimeWithOneSlot) {
  test::TempDir dir;
  LocalExecutor executor(1);
  for (const char* id : {"a", "b", "c"}) executor.submit(shell_job(id, exclusive("lock"), dir));
  const auto results = wait_for_all(executor, 20s);
  ASSERT_EQ(results.size(), 3u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
}

TEST(LocalExecutor, SerializesJobsPerGpuDeviceButNotAcrossDevices) {
  test::TempDir dir;
  LocalExecutor executor(8);
  for (const char* id : {"g1", "g2", "g3"}) executor.submit(shell_job(id, exclusive("gpu0"), dir, "cuda:0"));
  executor.submit(shell_job("x", rendezvous("x.started", "y.started"), dir, "cuda:1"));
  executor.submit(shell_job("y", rendezvous("y.started", "x.started"), dir, "cuda:2"));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 5u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
}

// Records the GPUs the job sees in <id>.gpu, holding the lock of that GPU meanwhile.
std::string record_gpu(const std::string& id, const std::string& then = "sleep 0.2") {
  return "echo \"${CUDA_VISIBLE_DEVICES-unset}\" > " + id + ".gpu; mkdir \"lock-$CUDA_VISIBLE_DEVICES\" || exit 3; " +
         then + "; rmdir \"lock-$CUDA_VISIBLE_DEVICES\"";
}

std::string gpu_seen(const test::TempDir& dir, const std::string& id) {
  std::string text = read_text_file(dir / (id + ".gpu"));
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

// Sets an environment variable for a test's duration.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnvironment() { old_ ? (void)::setenv(name_, old_->c_str(), 1) : (void)::unsetenv(name_); }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(LocalExecutor, SpreadsCudaJobsOverItsGpusEachPinnedToOneOfThem) {
  test::TempDir dir;
  const ScopedEnvironment machine("CUDA_VISIBLE_DEVICES", "0,1,2,3");
  LocalExecutor executor(1, {"2", "GPU-7f3a"});  // one CPU slot: GPU jobs do not take CPU slots
  // a and b only succeed when they run at the same time: on two GPUs at once.
  executor.submit(shell_job("a", record_gpu("a", rendezvous("a.started", "b.started")), dir, "cuda"));
  executor.submit(shell_job("b", record_gpu("b", rendezvous("b.started", "a.started")), dir, "cuda"));
  for (const char* id : {"c", "d", "e"}) executor.submit(shell_job(id, record_gpu(id), dir, "cuda"));
  executor.submit(shell_job("cpu", "sleep 0.1", dir));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 6u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
  EXPECT_NE(gpu_seen(dir, "a"), gpu_seen(dir, "b"));
  for (const char* id : {"a", "b", "c", "d", "e"}) {
    const std::string gpu = gpu_seen(dir, id);
    EXPECT_TRUE(gpu == "2" || gpu == "GPU-7f3a") << id << " saw CUDA_VISIBLE_DEVICES=" << gpu;
    EXPECT_NE(read_text_file(dir / ("logs/" + std::string(id) + ".log")).find(" on GPU " + gpu + ", "),
              std::string::npos);
  }
}

TEST(LocalExecutor, AJobOfSeveralGpusWaitsForThatManyFreeOnesAndIsPinnedToAllOfThem) {
  test::TempDir dir;
  const ScopedEnvironment machine("CUDA_VISIBLE_DEVICES", "0,1,2");
  LocalExecutor executor(1, {"0", "1", "2"});
  const auto on_gpus = [&](const std::string& id, int count, const std::string& script) {
    Job job = shell_job(id, script, dir, "cuda");
    job.resources.gpu_count = count;
    return job;
  };
  // one (1 GPU) and pair (2 GPUs) only succeed together: on three GPUs at once. Then second_pair
  // must wait until two are free, holding its lock alone.
  executor.submit(on_gpus("one", 1, record_gpu("one", rendezvous("one.started", "pair.started"))));
  executor.submit(on_gpus("pair", 2, record_gpu("pair", rendezvous("pair.started", "one.started"))));
  executor.submit(on_gpus("second_pair", 2, record_gpu("second_pair")));
  executor.submit(on_gpus("too_many", 4, "true"));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 4u);
  for (const auto& r : results) {
    if (r.id == "too_many") {
      EXPECT_FALSE(r.succeeded);
      EXPECT_NE(r.failure.find("needs 4 GPUs at once and this run has 3"), std::string::npos) << r.failure;
    } else {
      EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
    }
  }
  const std::string one = gpu_seen(dir, "one"), pair = gpu_seen(dir, "pair");
  EXPECT_EQ(pair.size(), 3u) << pair;  // two of the three, e.g. "0,1"
  EXPECT_EQ(pair.find(one), std::string::npos) << one << " is also in " << pair;
  EXPECT_EQ(gpu_seen(dir, "second_pair").size(), 3u);
  EXPECT_NE(read_text_file(dir / "logs/pair.log").find(" on GPUs " + pair + ", "), std::string::npos);
}

TEST(LocalExecutor, AJobWaitingForSeveralGpusIsNotOvertakenByLaterOnes) {
  test::TempDir dir;
  LocalExecutor executor(4, {"0", "1"});
  const auto on_gpus = [&](const std::string& id, int count, const std::string& script) {
    Job job = shell_job(id, script, dir, "cuda");
    job.resources.gpu_count = count;
    return job;
  };
  executor.submit(on_gpus("first", 1, "sleep 0.3"));
  executor.submit(on_gpus("pair", 2, "touch pair.started; sleep 0.1"));
  // GPU 1 is free from the start: taking it would keep pair waiting.
  executor.submit(on_gpus("later", 1, "[ -e pair.started ] || exit 5"));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 3u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
}

// Records the job's GPU in <id>.gpu and runs on it, failing when more than `most` jobs (its own
// included) are on that GPU at either of two moments; `then` runs between them.
std::string on_shared_gpu(const std::string& id, int most, const std::string& then = "sleep 0.1") {
  const std::string mine = "running-$CUDA_VISIBLE_DEVICES-" + id;
  const std::string check =
      "[ $(ls running-$CUDA_VISIBLE_DEVICES-* | wc -l) -le " + std::to_string(most) + " ] || exit 3";
  return "echo $CUDA_VISIBLE_DEVICES > " + id + ".gpu; touch " + mine + "; sleep 0.1; " + check + "; " + then +
         "; " + check + "; rm " + mine;
}

TEST(LocalExecutor, JobsThatShareAGpuRunUpToTheirBoundOnTheLeastBusyGpu) {
  test::TempDir dir;
  const ScopedEnvironment machine("CUDA_VISIBLE_DEVICES", "0,1");
  LocalExecutor executor(1, {"0", "1"});
  const auto sharing = [&](const std::string& id, int jobs_per_gpu, const std::string& script) {
    Job job = shell_job(id, script, dir, "cuda");
    job.resources.jobs_per_gpu = jobs_per_gpu;
    return job;
  };
  // a to d, two a GPU, only succeed when all four run at once; then e waits for room beside two,
  // and alone, which takes a GPU by itself, waits for an idle one and keeps others off it.
  const std::string all_four = "touch $0.started; i=0; while [ $(ls *.started | wc -l) -lt 4 ]; do i=$((i+1)); "
                               "[ $i -gt 300 ] && exit 4; sleep 0.01; done";
  for (const char* id : {"a", "b", "c", "d"}) {
    Job job = sharing(id, 2, on_shared_gpu(id, 2, all_four));
    job.argv.push_back(id);  // $0 of the script
    executor.submit(job);
  }
  executor.submit(sharing("alone", 1, on_shared_gpu("alone", 1)));
  executor.submit(sharing("e", 2, on_shared_gpu("e", 2)));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 6u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
  EXPECT_NE(gpu_seen(dir, "a"), gpu_seen(dir, "b")) << "b shares a GPU while the other is idle";
}

TEST(LocalExecutor, JobsShareTheCoresAmongThoseRunning) {
  test::TempDir dir;
  const ScopedEnvironment orchestrator("OMP_NUM_THREADS", "64");  // replaced, not inherited
  LocalExecutor executor(4, {}, std::chrono::seconds(5), /*cores=*/8);
  const auto threads_seen = [](const std::string& id) { return "echo $TEGA_THREADS $OMP_NUM_THREADS > " + id + ".threads"; };
  // Four at once share 8 cores, 2 threads each; then one alone has all of them.
  for (const char* id : {"a", "b", "c", "d"})
    executor.submit(shell_job(id, threads_seen(id) + "; " + rendezvous(std::string(id) + ".started", "d.started"), dir));
  ASSERT_EQ(wait_for_all(executor, 20s).size(), 4u);
  executor.submit(shell_job("alone", threads_seen("alone"), dir));
  ASSERT_EQ(wait_for_all(executor, 20s).size(), 1u);
  for (const char* id : {"a", "b", "c", "d"}) EXPECT_EQ(read_text_file(dir / (std::string(id) + ".threads")), "2 2\n");
  EXPECT_EQ(read_text_file(dir / "alone.threads"), "8 8\n");
  EXPECT_NE(read_text_file(dir / "logs/a.log").find("a, 2 threads: /bin/sh"), std::string::npos);
  EXPECT_NE(read_text_file(dir / "logs/alone.log").find("alone, 8 threads: "), std::string::npos);
}

TEST(LocalExecutor, WithoutGpusRunsCudaJobsOneAtATimeUnpinned) {
  test::TempDir dir;
  const ScopedEnvironment machine("CUDA_VISIBLE_DEVICES", "5,6");
  LocalExecutor executor(4);
  for (const char* id : {"a", "b", "c"}) executor.submit(shell_job(id, record_gpu(id), dir, "cuda"));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 3u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;  // the lock held
  for (const char* id : {"a", "b", "c"}) EXPECT_EQ(gpu_seen(dir, id), "5,6") << id;
}

TEST(LocalExecutor, AJobForOneDeviceWaitsForThePinnedJobOnItAndRunsUnpinned) {
  test::TempDir dir;
  const ScopedEnvironment machine("CUDA_VISIBLE_DEVICES", "0,1");
  LocalExecutor executor(4, {"1"});
  // pooled holds GPU 1 until a job on GPU 0 has started beside it; given, for GPU 1, must wait.
  executor.submit(shell_job("pooled",
                            "mkdir lock || exit 3; " + rendezvous("pooled.started", "other.started") +
                                "; sleep 0.2; rmdir lock",
                            dir, "cuda"));
  executor.submit(shell_job("given", "mkdir lock || exit 3; echo $CUDA_VISIBLE_DEVICES > given.gpu; rmdir lock", dir,
                            "cuda:1"));
  executor.submit(shell_job("other", rendezvous("other.started", "pooled.started"), dir, "cuda:0"));
  const auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 3u);
  for (const auto& r : results) EXPECT_TRUE(r.succeeded) << r.id << ": " << r.failure;
  EXPECT_EQ(gpu_seen(dir, "given"), "0,1");  // cuda:1 names the machine's device 1: not pinned
}

TEST(LocalExecutor, ReportsEachJobsPeakResidentMemory) {
  test::TempDir dir;
  LocalExecutor executor(2);
  executor.submit(shell_job("big", "python3 -c \"x = b'1' * (300 << 20)\"", dir));
  executor.submit(shell_job("small", "true", dir));
  auto results = wait_for_all(executor, 30s);
  ASSERT_EQ(results.size(), 2u);
  std::sort(results.begin(), results.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  ASSERT_TRUE(results[0].succeeded) << results[0].failure;
  EXPECT_GT(results[0].peak_rss_kib, 300 << 10);  // "big": 300 MiB of bytes, touched
  EXPECT_GT(results[1].peak_rss_kib, 0);
  EXPECT_LT(results[1].peak_rss_kib, 50 << 10);
}

TEST(LocalExecutor, ReportsFailuresAndAppendsOutputToTheLog) {
  test::TempDir dir;
  LocalExecutor executor(2);
  executor.submit(shell_job("fails", "echo something went wrong >&2; exit 7", dir));
  executor.submit([&] {
    Job job = shell_job("no-program", "", dir);
    job.argv = {(dir / "no-such-program").string()};
    return job;
  }());
  auto results = wait_for_all(executor, 20s);
  ASSERT_EQ(results.size(), 2u);
  std::map<std::string, JobResult> by_id;
  for (auto& r : results) by_id[r.id] = r;
  EXPECT_FALSE(by_id["fails"].succeeded);
  EXPECT_EQ(by_id["fails"].failure, "exit code 7");
  EXPECT_EQ(by_id["no-program"].failure, "exit code 127");
  const std::string log = read_text_file(dir / "logs/fails.log");
  EXPECT_EQ(log.rfind("=== ", 0), 0u) << log;
  EXPECT_NE(log.find("something went wrong"), std::string::npos) << log;
}

TEST(LocalExecutor, CancelStopsRunningJobsAndDropsQueuedOnes) {
  test::TempDir dir;
  LocalExecutor executor(1, {}, 2s);
  executor.submit(shell_job("sleeper", "touch started; sleep 60", dir));
  executor.submit(shell_job("queued", "touch queued-ran", dir));
  while (!std::filesystem::exists(dir / "started")) executor.wait(20ms);
  const auto start = std::chrono::steady_clock::now();
  executor.cancel_all();
  EXPECT_LT(std::chrono::steady_clock::now() - start, 2s);  // SIGTERM was enough
  EXPECT_EQ(executor.unfinished(), 0u);
  EXPECT_TRUE(executor.wait(100ms).empty());
  EXPECT_FALSE(std::filesystem::exists(dir / "queued-ran"));
}

}  // namespace
}  // namespace tega::pipeline
