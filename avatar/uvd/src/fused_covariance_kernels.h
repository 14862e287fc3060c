#pragma once
// CUDA kernels of world_covariance_packed (float and double): raw device
// pointers; the torch glue allocates the outputs and picks the stream.
// jacobian [N,3,3], quaternion [N,4], log_scale [N,3], covariance [N,6],
// std_per_scale [N,3] and the gradients of the same shapes, all contiguous.

#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::uvd::fused_covariance::cuda {

template <typename T>
void forward(int64_t n, const T* jacobian, const T* quaternion, const T* log_scale, T* covariance, T* std_per_scale,
             cudaStream_t stream);

template <typename T>
void backward(int64_t n, const T* jacobian, const T* quaternion, const T* log_scale, const T* grad_covariance,
              T* grad_jacobian, T* grad_quaternion, T* grad_log_scale, cudaStream_t stream);

}  // namespace tega::uvd::fused_covariance::cuda
