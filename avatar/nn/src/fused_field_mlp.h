#pragma once
// FieldMLP (tega/nn/field_mlp.h) as two fused CUDA kernels, one for the
// forward pass with its tangents and one for the backward pass
// (fused_field_mlp.cu says how). They replace the cuBLAS products and SiLU
// kernels of the bfloat16 path on CUDA, with the same precision: bfloat16
// matrix inputs, float32 accumulation, float32 outputs and weight gradients.
// The composed path in field_mlp.cpp stays the reference that tests compare
// against. First-order differentiable.

#include <ATen/core/Tensor.h>

#include "tega/nn/field_mlp.h"

namespace tega::nn::fused_field {

struct Parameters {
  at::Tensor input_weight, input_bias, hidden_weight, hidden_bias, output_weight, output_bias;  // float32
};

// Whether the kernels take this field and these inputs: CUDA tensors of a
// build with the kernels, a GPU with bfloat16 tensor cores (compute
// capability 8.0 or newer), bfloat16 encoding, 64 hidden channels, at most
// 8 outputs, a condition of a multiple of 16 channels (or none), at most 16
// encoding features per axis, and float32 parameters.
bool supports(const FieldMLPOptions& options, const EncodedPositions& encoded, const at::Tensor& input_weight);

// value [N, outputs]; jacobian [N, outputs, 3] when `encoded` has
// derivatives, else undefined. condition [N, condition_channels] or undefined.
FieldWithJacobian evaluate(const FieldMLPOptions& options, const Parameters& parameters,
                           const EncodedPositions& encoded, const at::Tensor& condition);

}  // namespace tega::nn::fused_field
