#pragma once
// Launchers of shaded_sh's CUDA kernels (shaded_sh.cu): raw pointers, no
// torch types; half_over_c0 is ½ / Y_0^0. dc [N,3], rest [N,stored,3], shading [N], out and grad_out
// [N,used,3], all contiguous.

#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::trainer::shading_fold::cuda {

template <typename T>
void forward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading, T* out,
             cudaStream_t stream);

template <typename T>
void backward(int64_t n, int used, int stored, T half_over_c0, const T* dc, const T* rest, const T* shading,
              const T* grad_out, T* grad_dc, T* grad_rest, T* grad_shading, cudaStream_t stream);

}  // namespace tega::trainer::shading_fold::cuda
