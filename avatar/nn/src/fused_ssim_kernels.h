#pragma once
// CUDA kernels of the fused SSIM (float). They take raw device pointers; the
// torch glue (fused_ssim_cuda.cpp) allocates every buffer and picks the stream.

#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::ssim::cuda {

// `planes` row-major images of height x width, one after the other.
struct Shape {
  int64_t planes = 0;  // at most 65535 (the grid's z)
  int height = 0;
  int width = 0;
};

// How many per-block sums `forward` writes.
int64_t forward_block_count(const Shape& shape);

// Writes each block's sum of the SSIM map to block_sums and, unless d_maps is
// null, the map's partial derivatives to d_maps ([3, planes, height, width]:
// ∂m/∂μa, ∂m/∂E[a²], ∂m/∂E[ab], ssim_math.h).
void forward(const Shape& shape, const float* a, const float* b, float* block_sums, float* d_maps,
             cudaStream_t stream);

// grad_a = *grad_output · scale · (blur(∂m/∂μa) + 2a blur(∂m/∂E[a²]) + b blur(∂m/∂E[ab])).
// grad_output is a device pointer, so that no host sync is needed.
void backward(const Shape& shape, const float* a, const float* b, const float* d_maps, const float* grad_output,
              float scale, float* grad_a, cudaStream_t stream);

}  // namespace tega::nn::ssim::cuda
