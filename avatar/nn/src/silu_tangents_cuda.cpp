// Torch glue of silu_with_tangents's CUDA kernels: outputs from the caching
// allocator, kernels on the current stream.

#include "silu_tangents_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "silu_tangents_kernels.h"

namespace tega::nn::silu_tangents {

std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& pre, const at::Tensor& tangents) {
  const c10::cuda::CUDAGuard guard(pre.device());
  at::Tensor value = at::empty_like(pre), out = at::empty_like(tangents);
  cuda::forward(pre.size(0), pre.size(1), pre.data_ptr<float>(), tangents.data_ptr<float>(), value.data_ptr<float>(),
                out.data_ptr<float>(), at::cuda::getCurrentCUDAStream());
  return {value, out};
}

std::pair<at::Tensor, at::Tensor> backward_cuda(const at::Tensor& pre, const at::Tensor& tangents,
                                                const at::Tensor& grad_value, const at::Tensor& grad_tangents) {
  const c10::cuda::CUDAGuard guard(pre.device());
  at::Tensor grad_pre = at::empty_like(pre), grad_t = at::empty_like(tangents);
  cuda::backward(pre.size(0), pre.size(1), pre.data_ptr<float>(), tangents.data_ptr<float>(),
                 grad_value.defined() ? grad_value.data_ptr<float>() : nullptr, grad_tangents.data_ptr<float>(),
                 grad_pre.data_ptr<float>(), grad_t.data_ptr<float>(), at::cuda::getCurrentCUDAStream());
  return {grad_pre, grad_t};
}

}  // namespace tega::nn::silu_tangents

#endif
