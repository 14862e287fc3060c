// Torch glue of silu_with_tangents's CUDA kernels: outputs from the caching
// allocator, kernels on the current stream.

#include "silu_tangents_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include <type_traits>

#include "silu_tangents_kernels.h"

namespace tega::nn::silu_tangents {
namespace {

// The kernels' element type for a tensor's dtype; at::BFloat16 and
// __nv_bfloat16 are both one IEEE bfloat16 in 16 bits.
template <typename S>
S* pointer(const at::Tensor& t) {
  if constexpr (std::is_same_v<S, float>) return t.data_ptr<float>();
  else return reinterpret_cast<S*>(t.data_ptr<at::BFloat16>());
}

template <typename S>
std::pair<at::Tensor, at::Tensor> forward_as(const at::Tensor& pre, const at::Tensor& tangents) {
  at::Tensor value = at::empty_like(pre), out = at::empty_like(tangents);
  cuda::forward(pre.size(0), pre.size(1), pointer<S>(pre), pointer<S>(tangents), pointer<S>(value), pointer<S>(out),
                at::cuda::getCurrentCUDAStream());
  return {value, out};
}

template <typename S>
std::pair<at::Tensor, at::Tensor> backward_as(const at::Tensor& pre, const at::Tensor& tangents,
                                              const at::Tensor& grad_value, const at::Tensor& grad_tangents) {
  at::Tensor grad_pre = at::empty_like(pre), grad_t = at::empty_like(tangents);
  cuda::backward(pre.size(0), pre.size(1), pointer<S>(pre), pointer<S>(tangents),
                 grad_value.defined() ? pointer<S>(grad_value) : nullptr, pointer<S>(grad_tangents),
                 pointer<S>(grad_pre), pointer<S>(grad_t), at::cuda::getCurrentCUDAStream());
  return {grad_pre, grad_t};
}

}  // namespace

std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& pre, const at::Tensor& tangents) {
  const c10::cuda::CUDAGuard guard(pre.device());
  if (pre.scalar_type() == at::kBFloat16) return forward_as<__nv_bfloat16>(pre, tangents);
  return forward_as<float>(pre, tangents);
}

std::pair<at::Tensor, at::Tensor> backward_cuda(const at::Tensor& pre, const at::Tensor& tangents,
                                                const at::Tensor& grad_value, const at::Tensor& grad_tangents) {
  const c10::cuda::CUDAGuard guard(pre.device());
  if (pre.scalar_type() == at::kBFloat16) return backward_as<__nv_bfloat16>(pre, tangents, grad_value, grad_tangents);
  return backward_as<float>(pre, tangents, grad_value, grad_tangents);
}

}  // namespace tega::nn::silu_tangents

#endif
