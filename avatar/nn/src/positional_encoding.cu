// One thread per (point, axis): it writes the axis's channels of the point's
// encoding row (every third channel; the three threads of a point are
// neighbours, so a warp's stores cover ~10 rows contiguously) and, when
// wanted, the axis's row of derivatives. The math runs in float; bfloat16
// storage halves what the first layer's products read.

#include <cuda_bf16.h>

#include <algorithm>

#include "positional_encoding_kernels.h"
#include "positional_encoding_math.h"
#include "tega/avatar/cuda_check.h"

namespace tega::nn::positional_encoding::cuda {
namespace {

constexpr int kThreads = 256;

__device__ float load(float x) { return x; }
__device__ float load(__nv_bfloat16 x) { return __bfloat162float(x); }
__device__ void store(float x, float* p) { *p = x; }
__device__ void store(float x, __nv_bfloat16* p) { *p = __float2bfloat16(x); }

__device__ float axis_scale(const Shape& s, int axis) { return axis == 2 ? s.depth_scale : 1.0f; }

template <typename S>
__global__ void forward_kernel(Shape s, const float* __restrict__ uvd, S* __restrict__ encoding,
                               S* __restrict__ derivatives) {
  const int features = 1 + 2 * s.frequencies;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < s.points * kAxes;
       i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t n = i / kAxes;
    const int a = int(i - n * kAxes);
    S* row = encoding + n * s.encoding_width;
    S* derivative_row = derivatives ? derivatives + (a * s.points + n) * s.derivative_width : nullptr;
    visit_features(s.frequencies, uvd[i], axis_scale(s, a), [&](int f, const Feature<float>& feature) {
      store(feature.value, row + 3 * f + a);
      if (derivative_row) store(feature.first, derivative_row + f);
    });
    for (int64_t c = 3 * features + a; c < s.encoding_width; c += kAxes) store(0.0f, row + c);
    if (derivative_row)
      for (int64_t f = features; f < s.derivative_width; ++f) store(0.0f, derivative_row + f);
  }
}

template <typename S>
__global__ void backward_kernel(Shape s, const float* __restrict__ uvd, const S* __restrict__ grad_encoding,
                                const S* __restrict__ grad_derivatives, float* __restrict__ grad_uvd) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < s.points * kAxes;
       i += int64_t(gridDim.x) * blockDim.x) {
    const int64_t n = i / kAxes;
    const int a = int(i - n * kAxes);
    const S* row = grad_encoding + n * s.encoding_width;
    const S* derivative_row =
        grad_derivatives ? grad_derivatives + (a * s.points + n) * s.derivative_width : nullptr;
    float grad = 0.0f;
    visit_features(s.frequencies, uvd[i], axis_scale(s, a), [&](int f, const Feature<float>& feature) {
      grad += load(row[3 * f + a]) * feature.first;
      if (derivative_row) grad += load(derivative_row[f]) * feature.second;
    });
    grad_uvd[i] = grad;
  }
}

unsigned blocks_for(int64_t count) { return unsigned(std::min<int64_t>((count + kThreads - 1) / kThreads, 1 << 20)); }

template <typename S>
void launch_forward(const Shape& shape, const float* uvd, S* encoding, S* derivatives, cudaStream_t stream) {
  if (shape.points == 0) return;
  forward_kernel<S><<<blocks_for(shape.points * kAxes), kThreads, 0, stream>>>(shape, uvd, encoding, derivatives);
  check_launch("encode_positions", "forward_kernel");
}

template <typename S>
void launch_backward(const Shape& shape, const float* uvd, const S* grad_encoding, const S* grad_derivatives,
                     float* grad_uvd, cudaStream_t stream) {
  if (shape.points == 0) return;
  backward_kernel<S><<<blocks_for(shape.points * kAxes), kThreads, 0, stream>>>(shape, uvd, grad_encoding,
                                                                                grad_derivatives, grad_uvd);
  check_launch("encode_positions", "backward_kernel");
}

}  // namespace

void forward(const Shape& shape, const float* uvd, float* encoding, float* derivatives, cudaStream_t stream) {
  launch_forward(shape, uvd, encoding, derivatives, stream);
}
void forward(const Shape& shape, const float* uvd, __nv_bfloat16* encoding, __nv_bfloat16* derivatives,
             cudaStream_t stream) {
  launch_forward(shape, uvd, encoding, derivatives, stream);
}
void backward(const Shape& shape, const float* uvd, const float* grad_encoding, const float* grad_derivatives,
              float* grad_uvd, cudaStream_t stream) {
  launch_backward(shape, uvd, grad_encoding, grad_derivatives, grad_uvd, stream);
}
void backward(const Shape& shape, const float* uvd, const __nv_bfloat16* grad_encoding,
              const __nv_bfloat16* grad_derivatives, float* grad_uvd, cudaStream_t stream) {
  launch_backward(shape, uvd, grad_encoding, grad_derivatives, grad_uvd, stream);
}

}  // namespace tega::nn::positional_encoding::cuda
