#pragma once
// CUDA kernels of fused_uvd_to_world (float and double): raw device pointers;
// the torch glue allocates the outputs and picks the stream. uvd [N,3],
// uv [N,2], triangle [N], xyz [N,3], jacobian [N,3,3] and the gradients of
// the same shapes, all contiguous.

#include <cuda_runtime_api.h>

#include <cstdint>

#include "fused_uvd_map_math.h"

namespace tega::uvd::fused_uvd_map::cuda {

template <typename T>
void forward(int64_t n, const Surface<T>& surface, const int64_t* triangle, const T* uv, const T* uvd, T* xyz,
             T* jacobian, cudaStream_t stream);

// grad_xyz and grad_jacobian may be null.
template <typename T>
void backward(int64_t n, const Surface<T>& surface, const int64_t* triangle, const T* uv, const T* uvd,
              const T* grad_xyz, const T* grad_jacobian, T* grad_uvd, cudaStream_t stream);

}  // namespace tega::uvd::fused_uvd_map::cuda
