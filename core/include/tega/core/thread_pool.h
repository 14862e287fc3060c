#pragma once
// A fixed pool of worker threads. parallel_for() splits an index range over
// the workers and rethrows the first exception a task threw.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <mutex>
#include <queue>
#include <thread>
#include <vector>

namespace tega {

// What a `threads: 0` option means: the environment's TEGA_THREADS where it is set (tega run
// gives each job its share of the cores there, and so may a user: TEGA_THREADS=8 tega ...), else
// one per core the process may run on (its affinity: taskset, a cpuset, a Slurm job's cores).
// Throws tega::Error when TEGA_THREADS is not a whole number >= 1.
int default_thread_count();

class ThreadPool {
 public:
  explicit ThreadPool(int threads = 0);  // 0: default_thread_count()
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()); }

  template <class F>
  auto submit(F&& task) -> std::future<std::invoke_result_t<F>> {
    using R = std::invoke_result_t<F>;
    auto packaged = std::make_shared<std::packaged_task<R()>>(std::forward<F>(task));
    auto future = packaged->get_future();
    enqueue([packaged] { (*packaged)(); });
    return future;
  }

  // Calls body(i) for every i in [begin, end), in chunks across the workers.
  void parallel_for(int64_t begin, int64_t end, const std::function<void(int64_t)>& body);

 private:
  void enqueue(std::function<void()> job);
  void work();

  std::vector<std::thread> workers_;
  std::queue<std::function<void()>> jobs_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
};

}  // namespace tega
