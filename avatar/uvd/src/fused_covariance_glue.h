#pragma once
// The CPU and CUDA implementations behind world_covariance_packed's autograd
// Function (fused_covariance.cpp). Inputs are contiguous, jacobian [N,3,3],
// quaternion [N,4], log_scale [N,3], of one floating dtype.

#include <ATen/core/Tensor.h>

#include <utility>

namespace tega::uvd::fused_covariance {

struct Gradients {
  at::Tensor jacobian, quaternion, log_scale;
};

// Returns (covariance [N,6], std_per_scale [N,3]).
std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                              const at::Tensor& log_scale);
Gradients backward_cpu(const at::Tensor& jacobian, const at::Tensor& quaternion, const at::Tensor& log_scale,
                       const at::Tensor& grad_covariance);
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                               const at::Tensor& log_scale);
Gradients backward_cuda(const at::Tensor& jacobian, const at::Tensor& quaternion, const at::Tensor& log_scale,
                        const at::Tensor& grad_covariance);
#endif

}  // namespace tega::uvd::fused_covariance
