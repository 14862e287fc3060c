// One thread per (row, channel): each reads its pre-activation once and its
// three tangent entries, which neighbouring threads read contiguously.

#include <algorithm>
#include <stdexcept>
#include <string>

#include "silu_tangents_kernels.h"
#include "silu_tangents_math.h"

namespace tega::nn::silu_tangents::cuda {
namespace {

constexpr int kThreads = 256;

void check_launch(const char* kernel) {
  const cudaError_t status = cudaGetLastError();
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("tega silu_with_tangents: launching ") + kernel + ": " + cudaGetErrorString(status));
}

__global__ void forward_kernel(int64_t count, int64_t width, const float* __restrict__ pre,
                               const float* __restrict__ tangents, float* __restrict__ h, float* __restrict__ u) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t row = i / width, column = i - row * width;
    const int64_t t = row * kAxes * width + column;
    forward_element(pre[i], tangents + t, width, h + i, u + t);
  }
}

__global__ void backward_kernel(int64_t count, int64_t width, const float* __restrict__ pre,
                                const float* __restrict__ tangents, const float* __restrict__ grad_h,
                                const float* __restrict__ grad_u, float* __restrict__ grad_x,
                                float* __restrict__ grad_t) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t row = i / width, column = i - row * width;
    const int64_t t = row * kAxes * width + column;
    backward_element(pre[i], tangents + t, grad_h ? grad_h + i : nullptr, grad_u + t, width, grad_x + i,
                     grad_t + t);
  }
}

unsigned blocks_for(int64_t count) {
  constexpr int64_t kMaxBlocks = 132 * 64;  // enough to fill an H100; the loops stride over the rest
  return unsigned(std::min<int64_t>((count + kThreads - 1) / kThreads, kMaxBlocks));
}

}  // namespace

void forward(int64_t rows, int64_t width, const float* pre, const float* tangents, float* h, float* u,
             cudaStream_t stream) {
  const int64_t count = rows * width;
  if (count == 0) return;
  forward_kernel<<<blocks_for(count), kThreads, 0, stream>>>(count, width, pre, tangents, h, u);
  check_launch("forward_kernel");
}

void backward(int64_t rows, int64_t width, const float* pre, const float* tangents, const float* grad_h,
              const float* grad_u, float* grad_x, float* grad_t, cudaStream_t stream) {
  const int64_t count = rows * width;
  if (count == 0) return;
  backward_kernel<<<blocks_for(count), kThreads, 0, stream>>>(count, width, pre, tangents, grad_h, grad_u, grad_x,
                                                              grad_t);
  check_launch("backward_kernel");
}

}  // namespace tega::nn::silu_tangents::cuda
