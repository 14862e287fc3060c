// Forward: a row of lanes per point (blockDim.x, the power of two covering
// its channel chunks, at most a warp), blockDim.y points per block. A lane
// reads V channels of each tap at once (V = 4: one 16-byte load, where the
// channels and pointers allow), so a point's loads and its store coalesce.
// Each lane works out its point's taps itself: a few instructions, against
// the division by the channel count that a thread per (point, channel) paid,
// which made the forward compute-bound (1.54 ms for 4M points of 64 channels).
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
// and chunk of channels. A lane takes kBatch points at a time: their loads
// are issued together, and their shuffle sums run side by side after them, so
// that a point's chain of dependent shuffles does not hold up the next
// point's texel checks (2.76 -> 2.55 ms a step for the trainer's two fields,
// 4M points of 64 channels on an H200).
//
// Launch shape: a warp is 32/width groups of `width` lanes, width = 32, or
// the power of two covering the channels when there are fewer. Lane `member`
// of a group takes channels chunk·M·width + m·width + member (m < M, M up to
// kMaxChannelsPerLane; more channels take several chunks, i.e. warps), so
// the loads of a point's channels are contiguous. The groups of a warp take
// interleaved points (group r: first + r, first + r + groups, ...), so each
// step's loads are contiguous too.

#include <climits>
#include <cstdint>
#include <stdexcept>

#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"
#include "latent_sampling_kernels.h"
#include "latent_sampling_math.h"

namespace tega::nn::latent_sampling::cuda {
namespace {

constexpr int kThreads = 256;
constexpr int kWarp = 32;
constexpr unsigned kFullWarp = 0xffffffffu;
constexpr int kRun = 64;  // points per group and warp in the backward pass
constexpr int kBatch = 4;  // points per group the backward takes at a time (kRun is a multiple)
constexpr int kMaxChannelsPerLane = 4;

// V channels of one point's sample: the taps' weighted sum at channel c.
template <int V>
__device__ void sample_channels(const float* __restrict__ latent, const Taps<float, int>& t, int C, int c,
                                float* __restrict__ out) {
  if constexpr (V == 4) {
    float4 sum = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
#pragma unroll
    for (int k = 0; k < 4; ++k) {
      const float4 x = *reinterpret_cast<const float4*>(latent + int64_t(t.texel[k]) * C + c);
      sum.x += t.weight[k] * x.x;
      sum.y += t.weight[k] * x.y;
      sum.z += t.weight[k] * x.z;
      sum.w += t.weight[k] * x.w;
    }
    *reinterpret_cast<float4*>(out) = sum;
  } else {
    float sum = 0.0f;
#pragma unroll
    for (int k = 0; k < 4; ++k) sum += t.weight[k] * latent[int64_t(t.texel[k]) * C + c];
    *out = sum;
  }
}

template <int V>
__global__ void forward_kernel(Shape s, const float* __restrict__ latent, const float* __restrict__ uv,
                               float* __restrict__ sampled) {
  const int64_t n = int64_t(blockIdx.x) * blockDim.y + threadIdx.y;
  if (n >= s.points) return;
  const int C = int(s.channels);
  const Taps<float, int> t = taps(uv[2 * n], uv[2 * n + 1], int(s.height), int(s.width));
  for (int c = int(threadIdx.x) * V; c < C; c += int(blockDim.x) * V)
    sample_channels<V>(latent, t, C, c, sampled + n * C + c);
}

// Launch: chunks · ceil(points / (kRun · 32/width)) warps, the chunks of one
// run adjacent (see backward()). M channels per lane; with a batch's loads
// held, M = 1 fits 64 registers without spilling (4 blocks of 256 per SM),
// M = 2 (the trainer's 64 channels) 80 (3 blocks), M = 3 and 4 128 (2).
template <int M>
__global__ void __launch_bounds__(kThreads, M == 1 ? 4 : M == 2 ? 3 : 2)
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

  for (int j0 = 0; j0 < kRun; j0 += kBatch) {
    if (first + int64_t(j0) * groups >= s.points) break;  // warp-uniform
    // The group's next kBatch points: every load issued before any is used.
    float batch_u[kBatch], batch_v[kBatch], batch_g[kBatch][M];
#pragma unroll
    for (int b = 0; b < kBatch; ++b) {
      const int64_t n = first + int64_t(j0 + b) * groups + group;
      const bool active = n < s.points;
      batch_u[b] = active ? uv[2 * n] : 0.0f;
      batch_v[b] = active ? uv[2 * n + 1] : 0.0f;
#pragma unroll
      for (int m = 0; m < M; ++m) batch_g[b][m] = active && has[m] ? grad_sampled[n * C + channel[m]] : 0.0f;
    }

    // This lane's shares of each point's ∂loss/∂u and ∂loss/∂v.
    float du[kBatch], dv[kBatch];
#pragma unroll
    for (int b = 0; b < kBatch; ++b) {
      du[b] = dv[b] = 0.0f;
      if (first + int64_t(j0 + b) * groups + group >= s.points) continue;
      const Taps<float, int> t = taps(batch_u[b], batch_v[b], int(s.height), int(s.width));
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
        float dot = 0.0f;  // this lane's share of ∂loss/∂weight[k]
#pragma unroll
        for (int m = 0; m < M; ++m) {
          sum[k][m] += t.weight[k] * batch_g[b][m];
          dot += value[k][m] * batch_g[b][m];
        }
        du[b] += t.dweight_du[k] * dot;
        dv[b] += t.dweight_dv[k] * dot;
      }
    }

    // Over the group's lanes, the batch's points side by side (their shuffles
    // do not wait on each other): even lanes sum du, odd lanes dv (one shuffle
    // halves the work), ending in members 0 and 1.
#pragma unroll
    for (int b = 0; b < kBatch; ++b) {
      const int64_t n = first + int64_t(j0 + b) * groups + group;
      const bool active = n < s.points;
      if (width == 1) {
        if (active) {
          atomicAdd(grad_uv + 2 * n, du[b]);
          atomicAdd(grad_uv + 2 * n + 1, dv[b]);
        }
      } else {
        const bool odd = member & 1;
        float total = odd ? dv[b] : du[b];
        total += __shfl_xor_sync(kFullWarp, odd ? du[b] : dv[b], 1);
        for (int offset = 2; offset < width; offset *= 2) total += __shfl_xor_sync(kFullWarp, total, offset);
        if (active && member < 2) atomicAdd(grad_uv + 2 * n + member, total);
      }
    }
  }
#pragma unroll
  for (int k = 0; k < 4; ++k) flush(k);
}

unsigned blocks_for(int64_t count) { return unsigned((count + kThreads - 1) / kThreads); }

// Texel indices and channels as int in the kernels, which is cheaper there.
void check_int_indices(const Shape& shape) {
  if (shape.height * shape.width > INT_MAX || shape.channels > INT_MAX)
    throw std::invalid_argument("tega sample_latent: the CUDA kernels take at most 2^31 - 1 texels and channels");
}

}  // namespace

void forward(const Shape& shape, const float* latent, const float* uv, float* sampled, cudaStream_t stream) {
  if (shape.points * shape.channels == 0) return;
  check_int_indices(shape);
  const bool by_four = shape.channels % 4 == 0 && aligned_to_16_bytes(latent) && aligned_to_16_bytes(sampled);
  const int64_t lane_chunks = by_four ? shape.channels / 4 : shape.channels;
  int lanes = 1;
  while (lanes < kWarp && lanes < lane_chunks) lanes *= 2;
  const dim3 block(lanes, kThreads / lanes);
  const unsigned blocks = unsigned((shape.points + block.y - 1) / block.y);
  if (by_four)
    forward_kernel<4><<<blocks, block, 0, stream>>>(shape, latent, uv, sampled);
  else
    forward_kernel<1><<<blocks, block, 0, stream>>>(shape, latent, uv, sampled);
  check_launch("sample_latent", "forward_kernel");
}

void backward(const Shape& shape, const float* latent, const float* uv, const float* grad_sampled,
              float* grad_latent, float* grad_uv, cudaStream_t stream) {
  if (shape.points * shape.channels == 0) return;
  check_int_indices(shape);
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
