// Forward: one thread per (point, channel); the threads of a point read its
// texels' channels contiguously (the latent is channels-last), so the loads
// coalesce.
//
// Backward: the trainer keeps the points sorted by their top-left tap
// (uv_order), so consecutive points mostly share their four taps. Each lane
// walks a run of kRun points for a few channels, holding per tap corner k the
// texel it last saw there, that texel's channel values and the gradient
// summed into it since. Only when corner k's texel changes, and at the end of
// the run, does the sum go to grad_latent with an atomic add: with ~60 points
// per texel about 30x fewer atomics than one per point and tap. Any order is
// still right (an unsorted one just flushes at every point). The uv gradient
// sums over the channels with warp shuffles, then one atomic add per point
// and chunk of channels.
//
// Launch shape: a warp is 32/width groups of `width` lanes, width = 32, or
// the power of two covering the channels when there are fewer. Lane `member`
// of a group takes channels chunk·M·width + m·width + member (m < M, M up to
// kMaxChannelsPerLane; more channels take several chunks, i.e. warps), so
// the loads of a point's channels are contiguous. The groups of a warp take
// interleaved points (group r: first + r, first + r + groups, ...), so each
// step's loads are contiguous too.

#include <climits>
#include <stdexcept>

#include "tega/core/cuda_check.h"
#include "latent_sampling_kernels.h"
#include "latent_sampling_math.h"

namespace tega::nn::latent_sampling::cuda {
namespace {

constexpr int kThreads = 256;
constexpr int kWarp = 32;
constexpr unsigned kFullWarp = 0xffffffffu;
constexpr int kRun = 64;  // points per group and warp in the backward pass
constexpr int kMaxChannelsPerLane = 4;

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

// Launch: chunks · ceil(points / (kRun · 32/width)) warps, the chunks of one
// run adjacent (see backward()). M channels per lane; M <= 2 (up to 64
// channels) fits 64 registers without spilling: 4 blocks of 256 per SM.
template <int M>
__global__ void __launch_bounds__(kThreads, M <= 2 ? 4 : 2)
    backward_kernel(Shape s, int width, int64_t chunks, const float* __restrict__ latent, const float* __restrict__ uv,
                    const float* __restrict__ grad_sampled, float* __restrict__ grad_latent,
                    float* __restrict__ grad_uv) {
  const int64_t warp = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) / kWarp;
  const int lane = int(threadIdx.x % kWarp), groups = kWarp / width;
  const int group = lane / width, member = lane % width;
  const int64_t chunk = warp % chunks, first = (warp / chunks) * kRun * groups;
  if (first >= s.points) return;  // the whole warp
  const int C = int(s.channels);

  int channel[M];
  bool has[M];
#pragma unroll
  for (int m = 0; m < M; ++m) {
    channel[m] = int(chunk * M + m) * width + member;
    has[m] = channel[m] < C;
  }

  // Per tap corner k: the texel held, its channel values, the gradient summed into it.
  int held[4] = {-1, -1, -1, -1};  // texel indices fit an int (checked in backward())
  float value[4][M], sum[4][M];
#pragma unroll
  for (int k = 0; k < 4; ++k)
#pragma unroll
    for (int m = 0; m < M; ++m) value[k][m] = sum[k][m] = 0.0f;

  auto flush = [&](int k) {
#pragma unroll
    for (int m = 0; m < M; ++m)
      if (has[m] && sum[k][m] != 0.0f) atomicAdd(grad_latent + int64_t(held[k]) * C + channel[m], sum[k][m]);
  };

  // Point j of the run, for this group; loads for point j+1 are issued before point j is processed.
  float u = 0.0f, v = 0.0f, g[M] = {};
  auto load = [&](int j) {
    const int64_t n = first + int64_t(j) * groups + group;
    if (n < s.points) {
      u = uv[2 * n];
      v = uv[2 * n + 1];
#pragma unroll
      for (int m = 0; m < M; ++m) g[m] = has[m] ? grad_sampled[n * C + channel[m]] : 0.0f;
    }
  };
  load(0);

  for (int j = 0; j < kRun; ++j) {
    const int64_t lead = first + int64_t(j) * groups;  // the warp's first point of this step
    if (lead >= s.points) break;                       // warp-uniform
    const int64_t n = lead + group;
    const bool active = n < s.points;
    const float pu = u, pv = v;
    float pg[M];
#pragma unroll
    for (int m = 0; m < M; ++m) pg[m] = g[m];
    if (j + 1 < kRun) load(j + 1);

    float du = 0.0f, dv = 0.0f;
    if (active) {
      const Taps<float, int> t = taps(pu, pv, int(s.height), int(s.width));
#pragma unroll
      for (int k = 0; k < 4; ++k) {
        if (t.texel[k] != held[k]) {
          flush(k);
          held[k] = t.texel[k];
#pragma unroll
          for (int m = 0; m < M; ++m) {
            sum[k][m] = 0.0f;
            value[k][m] = has[m] ? latent[int64_t(held[k]) * C + channel[m]] : 0.0f;
          }
        }
#pragma unroll
        for (int m = 0; m < M; ++m) {
          sum[k][m] += t.weight[k] * pg[m];
          const float vg = value[k][m] * pg[m];
          du += t.dweight_du[k] * vg;
          dv += t.dweight_dv[k] * vg;
        }
      }
    }

    // Over the group's lanes: even lanes sum du, odd lanes dv (one shuffle
    // halves the work), ending in members 0 and 1.
    if (width == 1) {
      if (active) {
        atomicAdd(grad_uv + 2 * n, du);
        atomicAdd(grad_uv + 2 * n + 1, dv);
      }
    } else {
      const bool odd = member & 1;
      float total = odd ? dv : du;
      total += __shfl_xor_sync(kFullWarp, odd ? du : dv, 1);
      for (int offset = 2; offset < width; offset *= 2) total += __shfl_xor_sync(kFullWarp, total, offset);
      if (active && member < 2) atomicAdd(grad_uv + 2 * n + member, total);
    }
  }
#pragma unroll
  for (int k = 0; k < 4; ++k) flush(k);
}

unsigned blocks_for(int64_t count) { return unsigned((count + kThreads - 1) / kThreads); }

}  // namespace

void forward(const Shape& shape, const float* latent, const float* uv, float* sampled, cudaStream_t stream) {
  const int64_t count = shape.points * shape.channels;
  if (count == 0) return;
  forward_kernel<<<blocks_for(count), kThreads, 0, stream>>>(shape, latent, uv, sampled);
  check_launch("sample_latent", "forward_kernel");
}

void backward(const Shape& shape, const float* latent, const float* uv, const float* grad_sampled,
              float* grad_latent, float* grad_uv, cudaStream_t stream) {
  if (shape.points * shape.channels == 0) return;
  if (shape.height * shape.width > INT_MAX || shape.channels > INT_MAX)
    throw std::invalid_argument("tega sample_latent: the CUDA backward takes at most 2^31 - 1 texels and channels");
  int width = 1;  // lanes per group: the channels' power of two, at most a warp
  while (width < kWarp && width < shape.channels) width *= 2;
  const int64_t lane_channels = (shape.channels + width - 1) / width;
  const int per_lane = int(lane_channels < kMaxChannelsPerLane ? lane_channels : kMaxChannelsPerLane);
  const int64_t chunks = (lane_channels + per_lane - 1) / per_lane;
  const int64_t run_points = int64_t(kRun) * (kWarp / width);
  const int64_t warps = chunks * ((shape.points + run_points - 1) / run_points);
  const unsigned blocks = blocks_for(warps * kWarp);
  auto kernel = per_lane == 1 ? backward_kernel<1>
                : per_lane == 2 ? backward_kernel<2>
                : per_lane == 3 ? backward_kernel<3>
                                : backward_kernel<4>;
  kernel<<<blocks, kThreads, 0, stream>>>(shape, width, chunks, latent, uv, grad_sampled, grad_latent, grad_uv);
  check_launch("sample_latent", "backward_kernel");
}

}  // namespace tega::nn::latent_sampling::cuda
