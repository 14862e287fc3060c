#pragma once
// The CPU and CUDA implementations behind sample_latent's autograd Function
// (latent_sampling.cpp). latent is channels-last [H, W, C], uv [N,2], both contiguous.

#include <ATen/core/Tensor.h>

#include <utility>

namespace tega::nn::latent_sampling {

at::Tensor forward_cpu(const at::Tensor& latent, const at::Tensor& uv);
// Returns (grad_latent [H,W,C], grad_uv [N,2]).
std::pair<at::Tensor, at::Tensor> backward_cpu(const at::Tensor& latent, const at::Tensor& uv,
                                               const at::Tensor& grad_sampled);
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
at::Tensor forward_cuda(const at::Tensor& latent, const at::Tensor& uv);
std::pair<at::Tensor, at::Tensor> backward_cuda(const at::Tensor& latent, const at::Tensor& uv,
                                                const at::Tensor& grad_sampled);
#endif

}  // namespace tega::nn::latent_sampling
