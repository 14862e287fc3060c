#pragma once
// Wall time per part of a training step (networks, Jacobians, rasterization,
// losses, densification, data). When enabled it waits for the device at every
// section boundary, which costs some speed, so it is off unless asked for
// (`tega train --profile`, bench/train).

#include <ATen/ATen.h>

#include <chrono>
#include <map>
#include <string>

namespace tega::trainer {

class StepProfiler {
 public:
  StepProfiler(bool enabled, const at::Device& device) : enabled_(enabled), device_(device) {}

  // Ends the running section (if any) and starts `name`.
  void section(const std::string& name);
  void stop();
  bool enabled() const { return enabled_; }
  // Milliseconds per recorded step, by section.
  std::map<std::string, double> mean_milliseconds(int64_t steps) const;

 private:
  void wait_for_device() const;

  bool enabled_;
  at::Device device_;
  std::string current_;
  std::chrono::steady_clock::time_point started_;
  std::map<std::string, double> total_seconds_;
};

}  // namespace tega::trainer
