// bench/train: milliseconds per TeGA training iteration, broken down by part
// (data, networks + Jacobians, rasterization, losses, backward, optimizer,
// densification), with peak GPU memory and the Gaussian count.
//
//   train_bench --data DATASET [--iterations 60] [--gaussians N] [--device cuda]
//               [--densify] [--set key=value ...] [--trace FILE]
//
// Without --densify the count stays at --gaussians, so a size (e.g. 4M at
// 3072x2048) is measured directly. The field and shading are active from the
// first iteration (no warm-up), as in the steady state of a real run.
//
// The profiled iterations are followed by as many unprofiled ones, timed by
// the wall clock as a user's run sees them. --trace (CUDA builds) records
// three more with the PyTorch (Kineto) profiler into a Chrome trace;
// bench/trace_summary.py turns it into GPU milliseconds per part of the
// model, forward and backward.

#include <ATen/ATen.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/trainer/trainer.h"

#ifdef TEGA_TORCH_HAS_CUDA
#include <c10/cuda/CUDACachingAllocator.h>

#include "kineto_trace.h"
#endif

namespace {

// Runs `work` under the Kineto profiler (CPU ops and CUDA kernels) and saves a Chrome trace.
template <class Work>
void trace_to(const std::string& path, Work&& work) {
#ifdef TEGA_TORCH_HAS_CUDA
  tega::bench::kineto_trace(path, work);
#else
  (void)work;
  throw tega::Error("--trace " + path + ": this build has no CUDA profiler");
#endif
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Times TeGA training iterations."};
  std::string data, device = "cuda";
  int64_t iterations = 60, gaussians = 500000;
  bool densify = false;
  std::vector<std::string> overrides;
  std::string trace;
  app.add_option("--data", data, "Dataset directory.")->required();
  app.add_option("--iterations", iterations, "Timed iterations (after 5 untimed warm-up iterations).")
      ->check(CLI::Range(int64_t(2), int64_t(1) << 40));
  app.add_option("--gaussians", gaussians, "Gaussians (initial count).");
  app.add_option("--device", device, "cpu or cuda.");
  app.add_flag("--densify", densify, "Keep densification on (the count then changes).");
  app.add_option("--set", overrides, "Training option override key=value (repeatable).");
  app.add_option("--trace", trace, "Chrome trace of three further iterations (Kineto; CUDA builds).");
  CLI11_PARSE(app, argc, argv);
  tega::init_logging(0);

  try {
    tega::trainer::TrainOptions options;
    options.device = device;
    options.iterations = iterations + 5;
    options.initial_gaussians = gaussians;
    options.warmup = 0.0;
    options.densify.enabled = densify;
    options.checkpoint_every = 1 << 30;
    options.log_every = 1 << 30;
    for (const auto& kv : overrides) {
      const auto eq = kv.find('=');
      tega::set_option(options, kv.substr(0, eq), kv.substr(eq + 1));
    }
    const auto run = std::filesystem::temp_directory_path() / "tega-train-bench";
    tega::remove_tree(run);

    // Warm-up slice (CUDA start-up, allocator growth), then the timed slice.
    tega::trainer::train(data, run, options, {.stop_at = 5});
    options.profile = true;
#ifdef TEGA_TORCH_HAS_CUDA
    if (device == "cuda") c10::cuda::CUDACachingAllocator::resetPeakStats(0);
#endif
    const auto summary = tega::trainer::train(data, run, options, {.resume = true});
    double peak_gib = 0;
#ifdef TEGA_TORCH_HAS_CUDA
    if (device == "cuda") {
      peak_gib = double(c10::cuda::CUDACachingAllocator::getDeviceStats(0).allocated_bytes[0].peak) / (1 << 30);
    }
#endif
    double total = 0;
    std::printf("train_bench: %s, %lld iterations, %lld Gaussians at the end, peak GPU memory %.2f GiB\n",
                data.c_str(), static_cast<long long>(summary.iterations), static_cast<long long>(summary.gaussians),
                peak_gib);
    std::printf("| part | ms / iteration |\n|---|---|\n");
    for (const auto& [part, ms] : summary.milliseconds_per_step) {
      std::printf("| %s | %.2f |\n", part.c_str(), ms);
      total += ms;
    }
    std::printf("| **total** | **%.2f** |\n", total);
    std::printf("(the profile waits for the GPU between parts; training without --profile overlaps them)\n");
    // The same number of iterations as training runs them, timed after the
    // first (which waits for the image loader's start): the rate a user sees.
    options.profile = false;
    options.iterations += iterations;
    const auto unprofiled = tega::trainer::train(data, run, options, {.resume = true});
    std::printf("unprofiled: %.2f ms / iteration over %lld iterations (wall clock, after the first)\n",
                1e3 * unprofiled.steady_seconds / double(unprofiled.steady_iterations),
                static_cast<long long>(unprofiled.steady_iterations));
    if (!trace.empty()) {
      options.iterations += 3;
      trace_to(trace, [&] { tega::trainer::train(data, run, options, {.resume = true}); });
      std::printf("trace of 3 iterations: %s\n", trace.c_str());
    }
  } catch (const tega::Error& e) {
    std::fprintf(stderr, "train_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
