// Torch glue of encode_positions's CUDA kernels: outputs from the caching
// allocator, kernels on the current stream.

#include "positional_encoding_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include <type_traits>

#include "positional_encoding_kernels.h"
#include "positional_encoding_math.h"

namespace tega::nn::positional_encoding {
namespace {

// at::BFloat16 and __nv_bfloat16 are both one IEEE bfloat16 in 16 bits.
template <typename S>
S* pointer(const at::Tensor& t) {
  if (!t.defined()) return nullptr;
  if constexpr (std::is_same_v<S, float>) return t.data_ptr<float>();
  else return reinterpret_cast<S*>(t.data_ptr<at::BFloat16>());
}

cuda::Shape shape_of(const PositionalEncoding& encoding, const at::Tensor& uvd) {
  cuda::Shape s;
  s.points = uvd.size(0);
  s.frequencies = int(encoding.frequencies);
  s.depth_scale = float(encoding.depth_scale);
  s.encoding_width = aligned_width(encoding.channels());
  s.derivative_width = aligned_width(encoding.features());
  return s;
}

template <typename S>
EncodedPositions forward_as(const PositionalEncoding& encoding, const at::Tensor& uvd, at::ScalarType type,
                            bool with_derivatives) {
  const cuda::Shape s = shape_of(encoding, uvd);
  const auto options = uvd.options().dtype(type);
  EncodedPositions out;
  out.encoding = at::empty({s.points, s.encoding_width}, options);
  if (with_derivatives) out.derivatives = at::empty({kAxes, s.points, s.derivative_width}, options);
  cuda::forward(s, uvd.data_ptr<float>(), pointer<S>(out.encoding), pointer<S>(out.derivatives),
                at::cuda::getCurrentCUDAStream());
  return out;
}

template <typename S>
at::Tensor backward_as(const PositionalEncoding& encoding, const at::Tensor& uvd, const at::Tensor& grad_encoding,
                       const at::Tensor& grad_derivatives) {
  at::Tensor grad_uvd = at::empty_like(uvd);
  cuda::backward(shape_of(encoding, uvd), uvd.data_ptr<float>(), pointer<S>(grad_encoding),
                 pointer<S>(grad_derivatives), grad_uvd.data_ptr<float>(), at::cuda::getCurrentCUDAStream());
  return grad_uvd;
}

}  // namespace

EncodedPositions forward_cuda(const PositionalEncoding& encoding, const at::Tensor& uvd, at::ScalarType type,
                              bool with_derivatives) {
  const c10::cuda::CUDAGuard guard(uvd.device());
  if (type == at::kBFloat16) return forward_as<__nv_bfloat16>(encoding, uvd, type, with_derivatives);
  return forward_as<float>(encoding, uvd, type, with_derivatives);
}

at::Tensor backward_cuda(const PositionalEncoding& encoding, const at::Tensor& uvd, const at::Tensor& grad_encoding,
                         const at::Tensor& grad_derivatives) {
  const c10::cuda::CUDAGuard guard(uvd.device());
  if (grad_encoding.scalar_type() == at::kBFloat16)
    return backward_as<__nv_bfloat16>(encoding, uvd, grad_encoding, grad_derivatives);
  return backward_as<float>(encoding, uvd, grad_encoding, grad_derivatives);
}

}  // namespace tega::nn::positional_encoding

#endif
