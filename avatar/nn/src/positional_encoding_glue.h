#pragma once
// The CPU and CUDA implementations behind encode_positions's autograd
// Function (positional_encoding.cpp). uvd is contiguous [N,3]; the outputs
// have aligned rows (tega/nn/positional_encoding.h).

#include <ATen/core/Tensor.h>

#include "tega/nn/positional_encoding.h"

namespace tega::nn::positional_encoding {

EncodedPositions forward_cpu(const PositionalEncoding& encoding, const at::Tensor& uvd, bool with_derivatives);
// grad_derivatives may be undefined.
at::Tensor backward_cpu(const PositionalEncoding& encoding, const at::Tensor& uvd, const at::Tensor& grad_encoding,
                        const at::Tensor& grad_derivatives);
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
EncodedPositions forward_cuda(const PositionalEncoding& encoding, const at::Tensor& uvd, at::ScalarType type,
                              bool with_derivatives);
at::Tensor backward_cuda(const PositionalEncoding& encoding, const at::Tensor& uvd, const at::Tensor& grad_encoding,
                         const at::Tensor& grad_derivatives);
#endif

}  // namespace tega::nn::positional_encoding
