#pragma once
// Runs `work` under the PyTorch (Kineto) profiler, CPU ops and CUDA kernels,
// and saves a Chrome trace for bench/trace_summary.py. CUDA builds only.

#include <torch/csrc/autograd/profiler_kineto.h>

#include <set>
#include <string>

namespace tega::bench {

template <class Work>
void kineto_trace(const std::string& path, Work&& work) {
  namespace profiler = torch::autograd::profiler;
  using torch::profiler::impl::ActivityType;
  const torch::profiler::impl::ProfilerConfig config(torch::profiler::impl::ProfilerState::KINETO);
  const std::set<ActivityType> activities{ActivityType::CPU, ActivityType::CUDA};
  profiler::prepareProfiler(config, activities);
  profiler::enableProfiler(config, activities);
  work();
  profiler::disableProfiler()->save(path);
}

}  // namespace tega::bench
