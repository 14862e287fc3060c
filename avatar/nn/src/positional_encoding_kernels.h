#pragma once
// CUDA kernels of encode_positions: raw device pointers; the torch glue
// allocates the outputs and picks the stream. uvd and grad_uvd are float
// [N,3]; the encoding [N, encoding_width] and the derivatives
// [3, N, derivative_width] are float or bfloat16.

#include <cuda_bf16.h>
#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::positional_encoding::cuda {

struct Shape {
  int64_t points = 0;
  int frequencies = 0;
  float depth_scale = 1.0f;
  int64_t encoding_width = 0, derivative_width = 0;
};

// derivatives may be null (not wanted).
void forward(const Shape& shape, const float* uvd, float* encoding, float* derivatives, cudaStream_t stream);
void forward(const Shape& shape, const float* uvd, __nv_bfloat16* encoding, __nv_bfloat16* derivatives,
             cudaStream_t stream);

// Writes grad_uvd; grad_derivatives may be null (no gradient reached them).
void backward(const Shape& shape, const float* uvd, const float* grad_encoding, const float* grad_derivatives,
              float* grad_uvd, cudaStream_t stream);
void backward(const Shape& shape, const float* uvd, const __nv_bfloat16* grad_encoding,
              const __nv_bfloat16* grad_derivatives, float* grad_uvd, cudaStream_t stream);

}  // namespace tega::nn::positional_encoding::cuda
