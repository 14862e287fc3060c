// shaded_sh's kernels. Forward: one thread per output element, so that reads
// and writes are coalesced. Backward: one thread per Gaussian, which sums
// its ∂s over its row.

#include <algorithm>

#include "shaded_sh_kernels.h"
#include "shaded_sh_math.h"
#include "tega/core/cuda_check.h"

namespace tega::trainer::shading_fold::cuda {
namespace {

constexpr int kThreads = 256;

unsigned blocks_for(int64_t count) {
  constexpr int64_t kMaxBlocks = 132 * 64;  // enough to fill an H100; the loops stride over the rest
  return unsigned(std::min<int64_t>((count + kThreads - 1) / kThreads, kMaxBlocks));
}

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

template <typename T>
__global__ void backward_kernel(int64_t n, int used, int stored, T half_over_c0, const T* __restrict__ dc,
                                const T* __restrict__ rest,
                                const T* __restrict__ shading, const T* __restrict__ grad_out, T* __restrict__ grad_dc,
                                T* __restrict__ grad_rest, T* __restrict__ grad_shading) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    grad_shading[i] = backward_row(dc + 3 * i, rest + 3 * stored * i, shading[i], half_over_c0, used, stored,
                                   grad_out + 3 * used * i, grad_dc + 3 * i, grad_rest + 3 * stored * i);
}

}  // namespace

template <typename T>
void forward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading, T* out,
             cudaStream_t stream) {
  if (n == 0) return;
  forward_kernel<<<blocks_for(n * 3 * used), kThreads, 0, stream>>>(n, used, stored, half_over_c0, dc, rest, shading,
                                                                    out);
  check_launch("shaded_sh", "forward_kernel");
}

template <typename T>
void backward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading,
              const T* grad_out, T* grad_dc, T* grad_rest, T* grad_shading, cudaStream_t stream) {
  if (n == 0) return;
  backward_kernel<<<blocks_for(n), kThreads, 0, stream>>>(n, used, stored, half_over_c0, dc, rest, shading, grad_out,
                                                          grad_dc, grad_rest, grad_shading);
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
