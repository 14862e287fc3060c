#pragma once
// CUDA kernels of silu_with_tangents (float32 or bfloat16 storage, float math):
// raw device pointers; the torch glue allocates the outputs and picks the
// stream. pre, h, grad_x are [N,H]; tangents, u, grad_u, grad_t are [N,3,H],
// all contiguous and all of one type.

#include <cuda_bf16.h>
#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::silu_tangents::cuda {

void forward(int64_t rows, int64_t width, const float* pre, const float* tangents, float* h, float* u,
             cudaStream_t stream);
void forward(int64_t rows, int64_t width, const __nv_bfloat16* pre, const __nv_bfloat16* tangents, __nv_bfloat16* h,
             __nv_bfloat16* u, cudaStream_t stream);

// grad_h may be null.
void backward(int64_t rows, int64_t width, const float* pre, const float* tangents, const float* grad_h,
              const float* grad_u, float* grad_x, float* grad_t, cudaStream_t stream);
void backward(int64_t rows, int64_t width, const __nv_bfloat16* pre, const __nv_bfloat16* tangents,
              const __nv_bfloat16* grad_h, const __nv_bfloat16* grad_u, __nv_bfloat16* grad_x, __nv_bfloat16* grad_t,
              cudaStream_t stream);

}  // namespace tega::nn::silu_tangents::cuda
