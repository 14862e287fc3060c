// One thread per Gaussian: its 16 inputs and 6 outputs are contiguous, and a
// warp's accesses cover contiguous memory, which the caches coalesce.

#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"
#include "fused_covariance_kernels.h"
#include "fused_covariance_math.h"

namespace tega::uvd::fused_covariance::cuda {
namespace {

constexpr int kThreads = 256;

template <typename T>
__global__ void forward_kernel(int64_t n, const T* __restrict__ jacobian, const T* __restrict__ quaternion,
                               const T* __restrict__ log_scale, T* __restrict__ covariance,
                               T* __restrict__ std_per_scale) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    forward_element(jacobian + 9 * i, quaternion + 4 * i, log_scale + 3 * i, covariance + 6 * i,
                    std_per_scale + 3 * i);
}

template <typename T>
__global__ void backward_kernel(int64_t n, const T* __restrict__ jacobian, const T* __restrict__ quaternion,
                                const T* __restrict__ log_scale, const T* __restrict__ grad_covariance,
                                T* __restrict__ grad_jacobian, T* __restrict__ grad_quaternion,
                                T* __restrict__ grad_log_scale) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    backward_element(jacobian + 9 * i, quaternion + 4 * i, log_scale + 3 * i, grad_covariance + 6 * i,
                     grad_jacobian + 9 * i, grad_quaternion + 4 * i, grad_log_scale + 3 * i);
}

}  // namespace

template <typename T>
void forward(int64_t n, const T* jacobian, const T* quaternion, const T* log_scale, T* covariance, T* std_per_scale,
             cudaStream_t stream) {
  if (n == 0) return;
  forward_kernel<<<grid_stride_blocks(n, kThreads), kThreads, 0, stream>>>(n, jacobian, quaternion, log_scale,
                                                                           covariance, std_per_scale);
  check_launch("world_covariance_packed", "forward_kernel");
}

template <typename T>
void backward(int64_t n, const T* jacobian, const T* quaternion, const T* log_scale, const T* grad_covariance,
              T* grad_jacobian, T* grad_quaternion, T* grad_log_scale, cudaStream_t stream) {
  if (n == 0) return;
  backward_kernel<<<grid_stride_blocks(n, kThreads), kThreads, 0, stream>>>(
      n, jacobian, quaternion, log_scale, grad_covariance, grad_jacobian, grad_quaternion, grad_log_scale);
  check_launch("world_covariance_packed", "backward_kernel");
}

template void forward<float>(int64_t, const float*, const float*, const float*, float*, float*, cudaStream_t);
template void forward<double>(int64_t, const double*, const double*, const double*, double*, double*, cudaStream_t);
template void backward<float>(int64_t, const float*, const float*, const float*, const float*, float*, float*, float*,
                              cudaStream_t);
template void backward<double>(int64_t, const double*, const double*, const double*, const double*, double*, double*,
                               double*, cudaStream_t);

}  // namespace tega::uvd::fused_covariance::cuda
