#pragma once
// CUDA kernels of sample_latent (float): raw device pointers; the torch glue
// allocates (and zeroes) the outputs and picks the stream. The latent is
// channels-last, [texels = H*W, C]; uv [N,2]; sampled and its gradient [N,C].

#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::latent_sampling::cuda {

struct Shape {
  int64_t points = 0, channels = 0, height = 0, width = 0;
};

void forward(const Shape& shape, const float* latent, const float* uv, float* sampled, cudaStream_t stream);

// Adds into grad_latent [texels, C] and grad_uv [N,2], which must start at zero.
void backward(const Shape& shape, const float* latent, const float* uv, const float* grad_sampled,
              float* grad_latent, float* grad_uv, cudaStream_t stream);

}  // namespace tega::nn::latent_sampling::cuda
