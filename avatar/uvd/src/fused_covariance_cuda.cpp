// Torch glue of world_covariance_packed's CUDA kernels: outputs from the
// caching allocator, kernels on the current stream.

#include "fused_covariance_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "fused_covariance_kernels.h"

namespace tega::uvd::fused_covariance {

std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                               const at::Tensor& log_scale) {
  const c10::cuda::CUDAGuard guard(jacobian.device());
  const int64_t n = jacobian.size(0);
  at::Tensor covariance = at::empty({n, 6}, jacobian.options()), std_per_scale = at::empty({n, 3}, jacobian.options());
  AT_DISPATCH_FLOATING_TYPES(jacobian.scalar_type(), "world_covariance_packed", [&] {
    cuda::forward(n, jacobian.data_ptr<scalar_t>(), quaternion.data_ptr<scalar_t>(), log_scale.data_ptr<scalar_t>(),
                  covariance.data_ptr<scalar_t>(), std_per_scale.data_ptr<scalar_t>(),
                  at::cuda::getCurrentCUDAStream());
  });
  return {covariance, std_per_scale};
}

Gradients backward_cuda(const at::Tensor& jacobian, const at::Tensor& quaternion, const at::Tensor& log_scale,
                        const at::Tensor& grad_covariance) {
  const c10::cuda::CUDAGuard guard(jacobian.device());
  Gradients grad{at::empty_like(jacobian), at::empty_like(quaternion), at::empty_like(log_scale)};
  AT_DISPATCH_FLOATING_TYPES(jacobian.scalar_type(), "world_covariance_packed_backward", [&] {
    cuda::backward(jacobian.size(0), jacobian.data_ptr<scalar_t>(), quaternion.data_ptr<scalar_t>(),
                   log_scale.data_ptr<scalar_t>(), grad_covariance.data_ptr<scalar_t>(),
                   grad.jacobian.data_ptr<scalar_t>(), grad.quaternion.data_ptr<scalar_t>(),
                   grad.log_scale.data_ptr<scalar_t>(), at::cuda::getCurrentCUDAStream());
  });
  return grad;
}

}  // namespace tega::uvd::fused_covariance

#endif
