// One thread per (row, channel): each reads its pre-activation once and its
// three tangent entries, which neighbouring threads read contiguously. The
// element math runs in float whatever the storage type: bfloat16 only halves
// the memory traffic, which is what bounds these kernels.

#include <cuda_bf16.h>

#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"
#include "silu_tangents_kernels.h"
#include "silu_tangents_math.h"

namespace tega::nn::silu_tangents::cuda {
namespace {

constexpr int kThreads = 256;

__device__ float load(float x) { return x; }
__device__ float load(__nv_bfloat16 x) { return __bfloat162float(x); }
__device__ void store(float x, float* p) { *p = x; }
__device__ void store(float x, __nv_bfloat16* p) { *p = __float2bfloat16(x); }

template <typename S>
__global__ void forward_kernel(int64_t count, int64_t width, const S* __restrict__ pre, const S* __restrict__ tangents,
                               S* __restrict__ h, S* __restrict__ u) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t row = i / width, column = i - row * width;
    const int64_t t = row * kAxes * width + column;
    float t_in[kAxes], u_out[kAxes], h_out;
#pragma unroll
    for (int a = 0; a < kAxes; ++a) t_in[a] = load(tangents[t + a * width]);
    forward_element(load(pre[i]), t_in, 1, &h_out, u_out);
    store(h_out, h + i);
#pragma unroll
    for (int a = 0; a < kAxes; ++a) store(u_out[a], u + t + a * width);
  }
}

template <typename S>
__global__ void backward_kernel(int64_t count, int64_t width, const S* __restrict__ pre,
                                const S* __restrict__ tangents, const S* __restrict__ grad_h,
                                const S* __restrict__ grad_u, S* __restrict__ grad_x, S* __restrict__ grad_t) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t row = i / width, column = i - row * width;
    const int64_t t = row * kAxes * width + column;
    float t_in[kAxes], gu_in[kAxes], gt_out[kAxes], gx_out;
#pragma unroll
    for (int a = 0; a < kAxes; ++a) {
      t_in[a] = load(tangents[t + a * width]);
      gu_in[a] = load(grad_u[t + a * width]);
    }
    // A missing gradient of the activation is passed as zero, not as null:
    // a pointer that may be null or point to a local puts it on the stack.
    const float gh_in = grad_h ? load(grad_h[i]) : 0.0f;
    backward_element(load(pre[i]), t_in, &gh_in, gu_in, 1, &gx_out, gt_out);
    store(gx_out, grad_x + i);
#pragma unroll
    for (int a = 0; a < kAxes; ++a) store(gt_out[a], grad_t + t + a * width);
  }
}

template <typename S>
void launch_forward(int64_t rows, int64_t width, const S* pre, const S* tangents, S* h, S* u, cudaStream_t stream) {
  const int64_t count = rows * width;
  if (count == 0) return;
  forward_kernel<<<grid_stride_blocks(count, kThreads), kThreads, 0, stream>>>(count, width, pre, tangents, h, u);
  check_launch("silu_with_tangents", "forward_kernel");
}

template <typename S>
void launch_backward(int64_t rows, int64_t width, const S* pre, const S* tangents, const S* grad_h, const S* grad_u,
                     S* grad_x, S* grad_t, cudaStream_t stream) {
  const int64_t count = rows * width;
  if (count == 0) return;
  backward_kernel<<<grid_stride_blocks(count, kThreads), kThreads, 0, stream>>>(count, width, pre, tangents, grad_h,
                                                                                grad_u, grad_x, grad_t);
  check_launch("silu_with_tangents", "backward_kernel");
}

}  // namespace

void forward(int64_t rows, int64_t width, const float* pre, const float* tangents, float* h, float* u,
             cudaStream_t stream) {
  launch_forward(rows, width, pre, tangents, h, u, stream);
}

void forward(int64_t rows, int64_t width, const __nv_bfloat16* pre, const __nv_bfloat16* tangents, __nv_bfloat16* h,
             __nv_bfloat16* u, cudaStream_t stream) {
  launch_forward(rows, width, pre, tangents, h, u, stream);
}

void backward(int64_t rows, int64_t width, const float* pre, const float* tangents, const float* grad_h,
              const float* grad_u, float* grad_x, float* grad_t, cudaStream_t stream) {
  launch_backward(rows, width, pre, tangents, grad_h, grad_u, grad_x, grad_t, stream);
}

void backward(int64_t rows, int64_t width, const __nv_bfloat16* pre, const __nv_bfloat16* tangents,
              const __nv_bfloat16* grad_h, const __nv_bfloat16* grad_u, __nv_bfloat16* grad_x, __nv_bfloat16* grad_t,
              cudaStream_t stream) {
  launch_backward(rows, width, pre, tangents, grad_h, grad_u, grad_x, grad_t, stream);
}

}  // namespace tega::nn::silu_tangents::cuda
