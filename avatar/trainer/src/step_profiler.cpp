#include "tega/trainer/step_profiler.h"

namespace tega::trainer {

void StepProfiler::wait_for_device() const {
  // Every kernel runs on the device's default stream, so copying one value
  // back waits for all work queued before it (and works with any libtorch).
  if (device_.is_cuda()) at::zeros({1}, at::TensorOptions().device(device_)).cpu();
}

void StepProfiler::section(const std::string& name) {
  if (!enabled_) return;
  stop();
  current_ = name;
  started_ = std::chrono::steady_clock::now();
}

void StepProfiler::stop() {
  if (!enabled_ || current_.empty()) return;
  wait_for_device();
  total_seconds_[current_] += std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  current_.clear();
}

std::map<std::string, double> StepProfiler::mean_milliseconds(int64_t steps) const {
  std::map<std::string, double> ms;
  for (const auto& [name, seconds] : total_seconds_) ms[name] = 1000.0 * seconds / static_cast<double>(std::max<int64_t>(1, steps));
  return ms;
}

}  // namespace tega::trainer
