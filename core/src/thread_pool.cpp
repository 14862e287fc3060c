#include "tega/core/thread_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>

namespace tega {

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = std::max(1u, std::thread::hardware_concurrency());
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
