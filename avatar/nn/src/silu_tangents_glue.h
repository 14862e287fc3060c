#pragma once
// The CPU and CUDA implementations behind silu_with_tangents's autograd
// Function (silu_tangents.cpp). Inputs are contiguous, pre [N,H], tangents [N,3,H].

#include <ATen/core/Tensor.h>

#include <utility>

namespace tega::nn::silu_tangents {

std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& pre, const at::Tensor& tangents);
// grad_value may be undefined; returns (grad_pre, grad_tangents).
std::pair<at::Tensor, at::Tensor> backward_cpu(const at::Tensor& pre, const at::Tensor& tangents,
                                               const at::Tensor& grad_value, const at::Tensor& grad_tangents);
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& pre, const at::Tensor& tangents);
std::pair<at::Tensor, at::Tensor> backward_cuda(const at::Tensor& pre, const at::Tensor& tangents,
                                                const at::Tensor& grad_value, const at::Tensor& grad_tangents);
#endif

}  // namespace tega::nn::silu_tangents
