#pragma once
// SiLU of a layer's pre-activations together with the forward-mode tangents
// that FieldMLP carries for its Jacobian (field_mlp.h), as one fused op:
//
//   value = silu(pre)                       [N,H]
//   tangents_out = silu'(pre) · tangents    [N,3,H] (broadcast over the axis)
//
// Composed from tensor ops this is ~6 kernels forward and ~12 backward over
// [N,64]-[N,3,64] tensors, the largest cost of training at millions of
// Gaussians; fused it reads and writes each tensor once per direction. CPU
// (float, double) and CUDA (float, bfloat16) share the element math
// (src/silu_tangents_math.h), which runs in float for bfloat16 tensors.
// First-order differentiable (no double backward).

#include <ATen/core/Tensor.h>

namespace tega::nn {

struct SiluWithTangents {
  at::Tensor value;     // [N,H]
  at::Tensor tangents;  // [N,3,H]
};

SiluWithTangents silu_with_tangents(const at::Tensor& pre, const at::Tensor& tangents);

}  // namespace tega::nn
