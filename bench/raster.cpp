// Rasterizer benchmark on a head-like scene: N Gaussians on a 0.2 m
// ellipsoid shell with log-normal scales of about 1 mm, SH degree 3, seen by
// a camera 1 m away with fx = fy = 2·width; loss = mean L1 to a random
// target. Prints forward and forward+backward times (median of 20 after 5
// warm-ups, CUDA events) and the peak GPU memory above the inputs.

#include <tega/splat/rasterize.h>

#include <ATen/ATen.h>
#include <torch/csrc/autograd/autograd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#if defined(TEGA_TORCH_HAS_CUDA)
#include <ATen/cuda/CUDAContext.h>
#include <ATen/record_function.h>
#include <c10/cuda/CUDACachingAllocator.h>
#include <cuda_runtime_api.h>

#include "kineto_trace.h"

namespace {

using namespace tega::splat;

constexpr int kWarmups = 5;
constexpr int kRepeats = 20;
constexpr double kMiB = 1024.0 * 1024.0;

struct Scene {
  at::Tensor means, covariances, sh, opacities, background, target;
};

Scene head_scene(int64_t n, int width, int height) {
  const auto opts = at::TensorOptions().dtype(at::kFloat).device(at::kCUDA);
  Scene s;
  const at::Tensor direction = at::randn({n, 3}, opts);
  const at::Tensor semi_axes = at::tensor({0.16f, 0.2f, 0.18f}, opts);
  s.means = direction / direction.norm(2, {1}, true) * semi_axes;
  const at::Tensor scales = at::exp(std::log(1e-3) + 0.3 * at::randn({n, 3}, opts));
  s.covariances = covariance_from_scale_rotation(scales, at::randn({n, 4}, opts));
  s.sh = at::randn({n, 16, 3}, opts) * 0.1;
  s.sh.select(1, 0).add_(0.5);
  s.opacities = 0.1 + 0.8 * at::rand({n}, opts);
  s.background = at::rand({3}, opts);
  s.target = at::rand({1, height, width, 3}, opts);
  for (at::Tensor* t : {&s.means, &s.covariances, &s.sh, &s.opacities, &s.background}) t->requires_grad_();
  return s;
}

struct Result {
  double forward_ms, forward_backward_ms, peak_mib, grads_mib;
};

template <typename F>
double median_ms(F&& run) {
  cudaStream_t stream = at::cuda::getCurrentCUDAStream();
  cudaEvent_t start, stop;
  cudaEventCreate(&start);
  cudaEventCreate(&stop);
  for (int i = 0; i < kWarmups; ++i) run();
  std::vector<float> times;
  for (int i = 0; i < kRepeats; ++i) {
    cudaEventRecord(start, stream);
    run();
    cudaEventRecord(stop, stream);
    cudaEventSynchronize(stop);
    float ms = 0;
    cudaEventElapsedTime(&ms, start, stop);
    times.push_back(ms);
  }
  cudaEventDestroy(start);
  cudaEventDestroy(stop);
  std::sort(times.begin(), times.end());
  return 0.5 * (times[kRepeats / 2 - 1] + times[kRepeats / 2]);
}

// The camera: 1 m from the head, fx = fy = 2 * width, SH degree 3.
std::pair<RasterCamera, RasterSettings> head_view(int width, int height) {
  RasterCamera camera;
  camera.translation = {0.0, 0.0, 1.0};
  camera.fx = camera.fy = 2.0 * width;
  camera.cx = 0.5 * width;
  camera.cy = 0.5 * height;
  RasterSettings settings;
  settings.width = width;
  settings.height = height;
  settings.sh_degree = 3;
  return {camera, settings};
}

Result measure(int64_t n, int width, int height) {
  const Scene s = head_scene(n, width, height);
  const auto [camera, settings] = head_view(width, height);
  const std::vector<at::Tensor> inputs = {s.means, s.covariances, s.sh, s.opacities, s.background};

  auto forward = [&] {
    return rasterize(s.means, s.covariances, s.sh, s.opacities, s.background, {camera}, settings);
  };
  auto forward_backward = [&] {
    const RasterOutput out = forward();
    const at::Tensor loss = (out.rgb - s.target).abs().mean();
    return torch::autograd::grad({loss}, inputs);
  };
  Result r{};
  r.forward_ms = median_ms([&] { forward(); });
  r.forward_backward_ms = median_ms([&] { forward_backward(); });

  const c10::DeviceIndex device = at::cuda::current_device();
  cudaDeviceSynchronize();
  const int64_t baseline = c10::cuda::CUDACachingAllocator::getDeviceStats(device).allocated_bytes[0].current;
  c10::cuda::CUDACachingAllocator::resetPeakStats(device);
  {
    const std::vector<at::Tensor> grads = forward_backward();
    cudaDeviceSynchronize();
    for (const at::Tensor& g : grads) r.grads_mib += double(g.numel() * g.element_size()) / kMiB;
  }
  const int64_t peak = c10::cuda::CUDACachingAllocator::getDeviceStats(device).allocated_bytes[0].peak;
  r.peak_mib = double(peak - baseline) / kMiB;
  return r;
}

// `raster_bench profile N WIDTH HEIGHT` runs two untimed forward+backward
// passes of one size, for a profiler (ncu) to time each kernel.
int profile(int64_t n, int width, int height) {
  const Scene s = head_scene(n, width, height);
  const auto [camera, settings] = head_view(width, height);
  for (int i = 0; i < 2; ++i) {
    const RasterOutput out = rasterize(s.means, s.covariances, s.sh, s.opacities, s.background, {camera}, settings);
    const at::Tensor loss = (out.rgb - s.target).abs().mean();
    torch::autograd::grad({loss}, {s.means, s.covariances, s.sh, s.opacities, s.background});
  }
  cudaDeviceSynchronize();
  return 0;
}

// `raster_bench trace N WIDTH HEIGHT FILE` records three forward+backward
// passes (after warm-ups) with the PyTorch (Kineto) profiler into a Chrome
// trace, each in a `tega::step` scope with the parts `tega::rasterize` and
// `tega::loss`: bench/trace_summary.py then reports the GPU's idle time,
// host overhead included, by part.
int trace(int64_t n, int width, int height, const std::string& path) {
  const Scene s = head_scene(n, width, height);
  const auto [camera, settings] = head_view(width, height);
  auto step = [&] {
    RECORD_FUNCTION("tega::step", std::vector<c10::IValue>());
    RasterOutput out;
    {
      RECORD_FUNCTION("tega::rasterize", std::vector<c10::IValue>());
      out = rasterize(s.means, s.covariances, s.sh, s.opacities, s.background, {camera}, settings);
    }
    at::Tensor loss;
    {
      RECORD_FUNCTION("tega::loss", std::vector<c10::IValue>());
      loss = (out.rgb - s.target).abs().mean();
    }
    torch::autograd::grad({loss}, {s.means, s.covariances, s.sh, s.opacities, s.background});
    cudaDeviceSynchronize();  // as the timed runs: each pass starts on an idle GPU
  };
  for (int i = 0; i < kWarmups; ++i) step();
  tega::bench::kineto_trace(path, [&] {
    for (int i = 0; i < 3; ++i) step();
  });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "profile") {
    if (!at::hasCUDA()) return 1;
    return profile(std::stoll(argv[2]), std::stoi(argv[3]), std::stoi(argv[4]));
  }
  if (argc == 6 && std::string(argv[1]) == "trace") {
    if (!at::hasCUDA()) return 1;
    return trace(std::stoll(argv[2]), std::stoi(argv[3]), std::stoi(argv[4]), argv[5]);
  }
  if (!at::hasCUDA()) {
    std::printf("raster_bench: no CUDA device, nothing to measure\n");
    return 0;
  }
  at::manual_seed(0);
  cudaDeviceProp prop{};
  cudaGetDeviceProperties(&prop, at::cuda::current_device());
  std::printf("raster_bench on %s: median of %d after %d warm-ups; memory = peak allocated above the inputs\n",
              prop.name, kRepeats, kWarmups);
  std::printf("(it includes the input gradients, listed separately)\n\n");
  std::printf("| Gaussians | image | forward ms | forward+backward ms | peak MiB | of which input grads MiB |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|\n");
  const int64_t sizes[] = {500'000, 1'000'000, 4'000'000};
  const int resolutions[][2] = {{1024, 667}, {2048, 1334}, {3072, 2048}};
  for (const int64_t n : sizes)
    for (const auto& res : resolutions) {
      const Result r = measure(n, res[0], res[1]);
      std::printf("| %.1fM | %dx%d | %.2f | %.2f | %.0f | %.0f |\n", double(n) / 1e6, res[0], res[1], r.forward_ms,
                  r.forward_backward_ms, r.peak_mib, r.grads_mib);
      std::fflush(stdout);
    }
  return 0;
}

#else

int main() {
  std::printf("raster_bench: built without CUDA libtorch, nothing to measure\n");
  return 0;
}

#endif
