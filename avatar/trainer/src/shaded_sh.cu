// shaded_sh's kernels, both coalesced. Forward: one thread per output
// element. Backward: one warp per Gaussian, its lanes along the row, ∂s summed
// across the warp; one thread per Gaussian read rows 192 bytes apart and took
// 7.9 ms at 4M Gaussians on an H200.

#include "shaded_sh_kernels.h"
#include "shaded_sh_math.h"
#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"

namespace tega::trainer::shading_fold::cuda {
namespace {

constexpr int kThreads = 256;
constexpr int kWarp = 32;

template <typename T>
__global__ void forward_kernel(int64_t n, int used, int stored, T half_over_c0, const T* __restrict__ dc,
                               const T* __restrict__ rest, const T* __restrict__ shading, T* __restrict__ out) {
  const int64_t width = 3 * int64_t(used), count = n * width;
  for (int64_t e = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; e < count; e += int64_t(gridDim.x) * blockDim.x) {
    const int64_t i = e / width;
    const int k = int(e - i * width);
    out[e] = forward_element(dc + 3 * i, rest + 3 * stored * i, shading[i], half_over_c0, k);
  }
}

// The row index is the same across a warp, so every lane takes part in each
// shuffle.
template <typename T>
__global__ void backward_kernel(int64_t n, int used, int stored, T half_over_c0, const T* __restrict__ dc,
                                const T* __restrict__ rest, const T* __restrict__ shading,
                                const T* __restrict__ grad_out, T* __restrict__ grad_dc, T* __restrict__ grad_rest,
                                T* __restrict__ grad_shading) {
  const int lane = int(threadIdx.x) % kWarp;
  const int64_t warps = int64_t(gridDim.x) * (blockDim.x / kWarp);
  const int width = 3 * (stored + 1);
  for (int64_t i = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) / kWarp; i < n; i += warps) {
    const T s = shading[i];
    T grad_s = T(0);
    for (int k = lane; k < width; k += kWarp) {
      T grad;
      grad_s += backward_element(dc + 3 * i, rest + 3 * stored * i, s, half_over_c0, used, k,
                                 grad_out + 3 * used * i, grad);
      if (k < 3) {
        grad_dc[3 * i + k] = grad;
      } else {
        grad_rest[3 * stored * i + k - 3] = grad;
      }
    }
    for (int offset = kWarp / 2; offset > 0; offset /= 2) grad_s += __shfl_down_sync(0xffffffffu, grad_s, offset);
    if (lane == 0) grad_shading[i] = grad_s;
  }
}

}  // namespace

template <typename T>
void forward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading, T* out,
             cudaStream_t stream) {
  if (n == 0) return;
  forward_kernel<<<grid_stride_blocks(n * 3 * used, kThreads), kThreads, 0, stream>>>(n, used, stored, half_over_c0,
                                                                                      dc, rest, shading, out);
  check_launch("shaded_sh", "forward_kernel");
}

template <typename T>
void backward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading,
              const T* grad_out, T* grad_dc, T* grad_rest, T* grad_shading, cudaStream_t stream) {
  if (n == 0) return;
  backward_kernel<<<grid_stride_blocks(n * kWarp, kThreads), kThreads, 0, stream>>>(
      n, used, stored, half_over_c0, dc, rest, shading, grad_out, grad_dc, grad_rest, grad_shading);
  check_launch("shaded_sh", "backward_kernel");
}

template void forward<float>(int64_t, int, int, float, const float*, const float*, const float*, float*,
                             cudaStream_t);
template void forward<double>(int64_t, int, int, double, const double*, const double*, const double*, double*,
                              cudaStream_t);
template void backward<float>(int64_t, int, int, float, const float*, const float*, const float*, const float*,
                              float*, float*, float*, cudaStream_t);
template void backward<double>(int64_t, int, int, double, const double*, const double*, const double*,
                               const double*, double*, double*, double*, cudaStream_t);

}  // namespace tega::trainer::shading_fold::cuda
