#include "tega/core/thread_pool.h"

#include <gtest/gtest.h>

#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <chrono>
#include <numeric>
#include <thread>

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/progress.h"

namespace {

TEST(ThreadPool, ParallelForVisitsEveryIndexOnce) {
  tega::ThreadPool pool(3);
  std::vector<std::atomic<int>> visits(1000);
  pool.parallel_for(0, 1000, [&](int64_t i) { visits[i]++; });
  for (auto& v : visits) EXPECT_EQ(v.load(), 1);
}

TEST(ThreadPool, ParallelForRethrowsTheFirstError) {
  tega::ThreadPool pool(2);
  EXPECT_THROW(pool.parallel_for(0, 100,
                                 [](int64_t i) {
                                   if (i == 37) throw std::runtime_error("bad index");
                                 }),
               std::runtime_error);
  // The pool still works afterwards.
  std::atomic<int64_t> sum{0};
  pool.parallel_for(0, 10, [&](int64_t i) { sum += i; });
  EXPECT_EQ(sum.load(), 45);
}

TEST(ThreadPool, ThreadsLeftToTheDefaultAreTegaThreadsWhereItIsSet) {
  const char* before = std::getenv("TEGA_THREADS");
  const std::string saved = before ? before : "";
  ::setenv("TEGA_THREADS", "3", 1);
  EXPECT_EQ(tega::default_thread_count(), 3);
  EXPECT_EQ(tega::ThreadPool().size(), 3);
  for (const char* bad : {"0", "-2", "many", "4 "}) {
    ::setenv("TEGA_THREADS", bad, 1);
    try {
      tega::default_thread_count();
      ADD_FAILURE() << bad << " was taken";
    } catch (const tega::Error& e) {
      EXPECT_NE(std::string(e.what()).find("TEGA_THREADS must be a whole number of threads, at least 1"),
                std::string::npos);
    }
  }
  ::unsetenv("TEGA_THREADS");
  // Unset: the cores this process may run on, as taskset or a Slurm job's binding leaves them.
  cpu_set_t all;
  ASSERT_EQ(::sched_getaffinity(0, sizeof all, &all), 0);
  EXPECT_EQ(tega::default_thread_count(), CPU_COUNT(&all));
  cpu_set_t one;
  CPU_ZERO(&one);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &all)) {
      CPU_SET(cpu, &one);
      break;
    }
  ASSERT_EQ(::sched_setaffinity(0, sizeof one, &one), 0);
  EXPECT_EQ(tega::default_thread_count(), 1);
  ASSERT_EQ(::sched_setaffinity(0, sizeof all, &all), 0);
  if (before) ::setenv("TEGA_THREADS", saved.c_str(), 1);
}

TEST(ThreadPool, SubmitReturnsResults) {
  tega::ThreadPool pool(2);
  auto a = pool.submit([] { return 6 * 7; });
  auto b = pool.submit([] { return std::string("ok"); });
  EXPECT_EQ(a.get(), 42);
  EXPECT_EQ(b.get(), "ok");
}

TEST(Progress, CountsFromManyThreadsAndFormatsDurations) {
  tega::ThreadPool pool(2);
  tega::Progress progress("test", 500, "items");
  pool.parallel_for(0, 500, [&](int64_t) { progress.advance(); });
  EXPECT_EQ(progress.done(), 500);
  EXPECT_EQ(tega::Progress::format_duration(125), "2:05");
  EXPECT_EQ(tega::Progress::format_duration(3723), "1:02:03");
  EXPECT_EQ(tega::Progress::format_duration(-1), "--:--");
}

// Under ctest stderr is not a terminal: the shape a shard's log gets.
TEST(Progress, LogsTheRateAndEtaEveryIntervalWhenStderrIsNotATerminal) {
  ASSERT_EQ(::isatty(STDERR_FILENO), 0);
  tega::init_logging(1);
  testing::internal::CaptureStderr();
  {
    tega::Progress progress("frames of x", 4, "frames", std::chrono::milliseconds(20));
    for (int i = 0; i < 4; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      progress.advance();
    }
  }
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("frames of x  1/4 frames"), std::string::npos) << log;
  EXPECT_NE(log.find("frames of x  3/4 frames"), std::string::npos) << log;
  EXPECT_NE(log.find("ETA 0:00"), std::string::npos) << log;
  EXPECT_NE(log.find("frames of x  4/4 frames"), std::string::npos) << log;
  EXPECT_NE(log.find(" in 0:00"), std::string::npos) << log;
  EXPECT_EQ(log.find('\r'), std::string::npos) << "no terminal redraws in a log";
}

}  // namespace
