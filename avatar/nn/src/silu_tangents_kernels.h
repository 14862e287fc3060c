#pragma once
// CUDA kernels of silu_with_tangents (float): raw device pointers; the torch
// glue allocates the outputs and picks the stream. pre, h, grad_x are [N,H];
// tangents, u, grad_u, grad_t are [N,3,H], all contiguous.

#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::silu_tangents::cuda {

void forward(int64_t rows, int64_t width, const float* pre, const float* tangents, float* h, float* u,
             cudaStream_t stream);

// grad_h may be null.
void backward(int64_t rows, int64_t width, const float* pre, const float* tangents, const float* grad_h,
              const float* grad_u, float* grad_x, float* grad_t, cudaStream_t stream);

}  // namespace tega::nn::silu_tangents::cuda
