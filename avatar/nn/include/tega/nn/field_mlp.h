#pragma once
// The small conditioned MLPs of TeGA §3.4–3.5, evaluated per Gaussian (or per
// random uvd sample):
//
//   y = L2(σ(L1(σ(L0([PE(uvd), f])))))      two hidden layers, σ = SiLU
//
// PE is a sinusoidal positional encoding of the (scaled) uvd position and f
// the latent feature sampled at the Gaussian's uv (absent when the network
// runs without latents). The last layer starts at zero, so a fresh field
// outputs exactly 0 (and a zero Jacobian).
//
// forward_with_jacobian() also returns ∂y/∂uvd without double backward: three
// tangent columns travel through the layers next to the activations
// (J ← J·Wᵀ for a linear layer, J ← σ'(pre-activation)·J for the activation)
// starting from the positional encoding's analytic derivative. The latent is
// a condition: it is not differentiated w.r.t. uvd. Autograd differentiates
// the Jacobian too (the smoothness loss and the covariance J Σ Jᵀ train the
// weights through it): through plain tensor algebra, or on CUDA through two
// fused kernels that compute the same (FieldMLPOptions::fused).
//
// SiLU rather than ReLU because J enters the Gaussians' covariances: with a
// smooth activation the Jacobian is continuous in uvd and its gradient w.r.t.
// the weights does not vanish in flat regions.

#include <ATen/core/Tensor.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/pimpl.h>

#include "tega/nn/positional_encoding.h"

#include <utility>
#include <vector>

namespace tega::nn {

// What the layers compute in on CUDA. kFloat32 keeps everything in the
// parameters' type (float32 in training). kBFloat16 stores the GEMM inputs,
// activations and tangents in bfloat16 (cuBLAS accumulates in float32),
// halving the memory traffic of the [N,3,hidden] tangents and [N,hidden]
// activations that bound the field's time at millions of Gaussians; the
// parameters, the positional encoding math and the outputs (value, Jacobian)
// stay in the parameters' type, and autograd trains the parameters through
// per-call casts of the weights. On the CPU the layers always run in the
// parameters' type.
enum class MlpPrecision { kFloat32, kBFloat16 };

struct FieldMLPOptions {
  int64_t condition_channels = 64;  // 0: no latent condition
  int64_t hidden = 64;
  int64_t outputs = 3;
  PositionalEncoding encoding;
  MlpPrecision precision = MlpPrecision::kBFloat16;
  // With bfloat16 on a GPU that has bfloat16 tensor cores, run the field as
  // two fused kernels (src/fused_field_mlp.h) when they take its widths
  // (64 hidden, ≤ 8 outputs); false keeps the composed cuBLAS path, the
  // reference the kernels are tested against.
  bool fused = true;
};

struct FieldWithJacobian {
  at::Tensor value;     // [N, outputs]
  at::Tensor jacobian;  // [N, outputs, 3]: ∂value_i / ∂uvd_j
};

class FieldMLPImpl : public torch::nn::Module {
 public:
  explicit FieldMLPImpl(const FieldMLPOptions& options);

  // The positional encoding of uvd [N,3] in the layers' type, with its
  // derivatives when a Jacobian is wanted. Fields with the same encoding and
  // precision options can share it (ExpressionNetwork computes it once for
  // both of its fields).
  EncodedPositions encode(const at::Tensor& uvd, bool with_derivatives) const;

  // condition [N, condition_channels] (undefined when 0 channels).
  at::Tensor forward(const EncodedPositions& encoded, const at::Tensor& condition);
  FieldWithJacobian forward_with_jacobian(const EncodedPositions& encoded, const at::Tensor& condition);
  // The same from uvd [N,3].
  at::Tensor forward(const at::Tensor& uvd, const at::Tensor& condition);
  FieldWithJacobian forward_with_jacobian(const at::Tensor& uvd, const at::Tensor& condition);

  const FieldMLPOptions& options() const { return options_; }
  // Whether these inputs run through the fused kernels (FieldMLPOptions::fused).
  bool runs_fused(const EncodedPositions& encoded) const;

 private:
  at::ScalarType layer_type(const at::Tensor& uvd) const;
  void check_encoded(const EncodedPositions& encoded, bool with_derivatives) const;
  // Pre-activation, with the first layer's weight already in the layers' type.
  at::Tensor first_layer(const EncodedPositions& encoded, const at::Tensor& condition, const at::Tensor& weight) const;
  // The output layer's weight and bias in the layers' type, rows padded to
  // an aligned count (positional_encoding.h says why).
  std::pair<at::Tensor, at::Tensor> output_layer(at::ScalarType type) const;
  FieldWithJacobian fused_forward(const EncodedPositions& encoded, const at::Tensor& condition) const;

  FieldMLPOptions options_;
  torch::nn::Linear input_{nullptr}, hidden_{nullptr}, output_{nullptr};
};
TORCH_MODULE(FieldMLP);

}  // namespace tega::nn
