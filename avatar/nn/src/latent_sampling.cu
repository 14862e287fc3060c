// One thread per (point, channel): the threads of a point read and write its
// texels' channels contiguously (the latent is channels-last), so the loads
// and the atomic adds of the latent's gradient coalesce. The uv gradient sums
// over channels with warp shuffles, then one atomic add per point and warp.


#include "tega/avatar/cuda_check.h"
#include "latent_sampling_kernels.h"
#include "latent_sampling_math.h"

namespace tega::nn::latent_sampling::cuda {
namespace {

constexpr int kThreads = 256;
constexpr unsigned kFullWarp = 0xffffffffu;

__global__ void forward_kernel(Shape s, const float* __restrict__ latent, const float* __restrict__ uv,
                               float* __restrict__ sampled) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= s.points * s.channels) return;
  const int64_t n = i / s.channels, c = i - n * s.channels;
  const Taps<float> t = taps(uv[2 * n], uv[2 * n + 1], s.height, s.width);
  float sum = 0.0f;
#pragma unroll
  for (int k = 0; k < 4; ++k) sum += t.weight[k] * latent[t.texel[k] * s.channels + c];
  sampled[i] = sum;
}

// Lanes [g·group, (g+1)·group) of a warp hold channels of one point when
// `group` divides the channel count and 32 (see backward()).
__global__ void backward_kernel(Shape s, int group, const float* __restrict__ latent, const float* __restrict__ uv,
                                const float* __restrict__ grad_sampled, float* __restrict__ grad_latent,
                                float* __restrict__ grad_uv) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const bool active = i < s.points * s.channels;
  float du = 0.0f, dv = 0.0f;
  int64_t n = 0;
  if (active) {
    n = i / s.channels;
    const int64_t c = i - n * s.channels;
    const Taps<float> t = taps(uv[2 * n], uv[2 * n + 1], s.height, s.width);
    const float g = grad_sampled[i];
#pragma unroll
    for (int k = 0; k < 4; ++k) {
      const int64_t at = t.texel[k] * s.channels + c;
      if (t.weight[k] != 0.0f) atomicAdd(grad_latent + at, t.weight[k] * g);
      const float value = latent[at];
      du += t.dweight_du[k] * value * g;
      dv += t.dweight_dv[k] * value * g;
    }
  }
  for (int offset = group / 2; offset > 0; offset /= 2) {
    du += __shfl_down_sync(kFullWarp, du, offset, group);
    dv += __shfl_down_sync(kFullWarp, dv, offset, group);
  }
  if (active && threadIdx.x % group == 0) {
    atomicAdd(grad_uv + 2 * n, du);
    atomicAdd(grad_uv + 2 * n + 1, dv);
  }
}

unsigned blocks_for(int64_t count) { return unsigned((count + kThreads - 1) / kThreads); }

// Largest power of two that divides both the channel count and the warp.
int lane_group(int64_t channels) {
  int group = 32;
  while (channels % group != 0) group /= 2;
  return group;
}

}  // namespace

void forward(const Shape& shape, const float* latent, const float* uv, float* sampled, cudaStream_t stream) {
  const int64_t count = shape.points * shape.channels;
  if (count == 0) return;
  forward_kernel<<<blocks_for(count), kThreads, 0, stream>>>(shape, latent, uv, sampled);
  check_launch("sample_latent", "forward_kernel");
}

void backward(const Shape& shape, const float* latent, const float* uv, const float* grad_sampled,
              float* grad_latent, float* grad_uv, cudaStream_t stream) {
  const int64_t count = shape.points * shape.channels;
  if (count == 0) return;
  backward_kernel<<<blocks_for(count), kThreads, 0, stream>>>(shape, lane_group(shape.channels), latent, uv,
                                                              grad_sampled, grad_latent, grad_uv);
  check_launch("sample_latent", "backward_kernel");
}

}  // namespace tega::nn::latent_sampling::cuda
