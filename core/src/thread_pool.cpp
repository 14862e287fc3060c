#include "tega/core/thread_pool.h"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <string>

#include "tega/core/error.h"

namespace tega {

namespace {

// The cores this process may run on: its affinity mask (taskset, a container's cpuset, a Slurm
// job's binding), which hardware_concurrency() ignores.
int usable_cores() {
  cpu_set_t set;
  if (::sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace

int default_thread_count() {
  const char* set = std::getenv("TEGA_THREADS");
  if (set == nullptr || *set == '\0') return usable_cores();
  const std::string text = set;
  if (text.size() > 6 || text.find_first_not_of("0123456789") != std::string::npos || std::stoi(text) < 1)
    throw Error("TEGA_THREADS must be a whole number of threads, at least 1 (it is '" + text + "')");
  return std::stoi(text);
}

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = default_thread_count();
  workers_.reserve(threads);
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& worker : workers_) worker.join();
}

void ThreadPool::enqueue(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    jobs_.push(std::move(job));
  }
  wake_.notify_one();
}

void ThreadPool::work() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
      if (jobs_.empty()) return;
      job = std::move(jobs_.front());
      jobs_.pop();
    }
    job();
  }
}

void ThreadPool::parallel_for(int64_t begin, int64_t end, const std::function<void(int64_t)>& body) {
  if (end <= begin) return;
  // Indices are handed out one at a time from a shared counter: iterations of
  // uneven cost (image rows, cameras) then balance by themselves.
  std::atomic<int64_t> next{begin};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const int tasks = static_cast<int>(std::min<int64_t>(size(), end - begin));
  std::vector<std::future<void>> running;
  running.reserve(tasks);
  for (int t = 0; t < tasks; ++t) {
    running.push_back(submit([&] {
      for (int64_t i = next++; i < end && !failed; i = next++) {
        try {
          body(i);
        } catch (...) {
          std::lock_guard lock(error_mutex);
          if (!first_error) first_error = std::current_exception();
          failed = true;
        }
      }
    }));
  }
  for (auto& r : running) r.wait();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace tega
