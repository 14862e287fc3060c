#pragma once
// TeGA's expression-dependent fields (§3.4–3.5, Fig. 3): an encoder turns the
// frame's UV displacement texture into latents; per Gaussian, the latents are
// sampled at its uv and condition two MLPs:
//
//   Δxyz = D(uvd; f_uv)               world-space residual translation (metres)
//   S    = 2·sigmoid(S'(uvd; f_uv^S)) monochrome shading factor, 1 at init
//
// `latent` selects the encoder (and the ablations):
//   "unet"   the paper's U-Net latent textures (default)
//   "global" the paper's "MLP" ablation: one code per expression (GlobalEncoder)
//   "none"   no latent at all; D and S see only PE(uvd), so they cannot depend
//            on the expression (a static correction field)
//
// The trainer keeps eyeball Gaussians out of D (the paper: eyes are rigid);
// this module evaluates whatever points it is given.

#include <ATen/core/Tensor.h>
#include <torch/nn/module.h>
#include <torch/nn/pimpl.h>

#include <string>
#include <vector>

#include "tega/nn/encoders.h"
#include "tega/nn/field_mlp.h"

namespace tega::nn {

struct NetworkOptions {
  std::string latent = "unet";
  int texture_size = 256;
  int latent_channels = 64;
  std::vector<int> unet_widths{32, 64, 128, 256};
  int global_layers = 8;
  double input_scale = 100.0;
  int mlp_hidden = 64;
  int pe_frequencies = 6;
  double pe_depth_scale = 3.0;
  std::string mlp_precision = "bfloat16";
  bool mlp_fused = true;

  template <class V>
  void visit(V& v) {
    v("latent", latent, "Expression encoder: unet (paper), global (one code per frame, the paper's MLP ablation) or none.");
    v("texture_size", texture_size, "Side N of the UV displacement texture and of the latent textures.");
    v("latent_channels", latent_channels, "Channels of each latent (deformation and shading).");
    v("unet_widths", unet_widths, "U-Net channels per level, full resolution first; N must be divisible by 2^(levels-1).");
    v("global_layers", global_layers, "Stride-2 conv layers of the global encoder (latent: global).");
    v("input_scale", input_scale, "Multiplies the displacement texture (metres) before the encoder.");
    v("mlp_hidden", mlp_hidden, "Width of the two hidden layers of the deformation and shading MLPs.");
    v("pe_frequencies", pe_frequencies, "Octaves of the sinusoidal positional encoding of uvd (pi * 2^k, k < this).");
    v("pe_depth_scale", pe_depth_scale, "Multiplies d (metres) before the positional encoding.");
    v("mlp_precision", mlp_precision,
      "What the deformation and shading MLPs' layers compute in on CUDA: float32, or bfloat16 (GEMM inputs, "
      "activations and Jacobian tangents; weights, encoding and outputs stay float32). On the CPU they always run "
      "in float32.");
    v("mlp_fused", mlp_fused,
      "With bfloat16 on a GPU with bfloat16 tensor cores (compute capability 8.0+) and mlp_hidden 64, run each MLP "
      "as two fused kernels (forward with its Jacobian, and backward) instead of cuBLAS products and separate "
      "activation kernels; false keeps the composed path.");
  }
};

struct Latents {
  at::Tensor deformation;  // [C,H,W] ([C,1,1] for "global"); undefined for "none"
  at::Tensor shading;
};

class ExpressionNetworkImpl : public torch::nn::Module {
 public:
  // Throws tega::Error for an unknown `latent` or `mlp_precision`, or inconsistent sizes.
  explicit ExpressionNetworkImpl(const NetworkOptions& options);

  // One frame's displacement texture [3,N,N] (metres) → its latents.
  Latents encode(const at::Tensor& displacement_texture);
  // The positional encoding of uvd [N,3] that both fields read (with its
  // derivatives when deform() is to return a Jacobian), computed once for both.
  EncodedPositions encode_positions(const at::Tensor& uvd, bool with_derivatives) const;
  // Δxyz [N,3] at uvd [N,3]; the Jacobian ∂Δxyz/∂uvd [N,3,3] too when asked.
  FieldWithJacobian deform(const at::Tensor& uvd, const EncodedPositions& encoded, const Latents& latents,
                           bool with_jacobian);
  // Shading factor [N] in (0, 2).
  at::Tensor shade(const at::Tensor& uvd, const EncodedPositions& encoded, const Latents& latents);
  // The same, encoding uvd for the one call.
  FieldWithJacobian deform(const at::Tensor& uvd, const Latents& latents, bool with_jacobian);
  at::Tensor shade(const at::Tensor& uvd, const Latents& latents);

  const NetworkOptions& options() const { return options_; }

 private:
  at::Tensor condition(const at::Tensor& latent, const at::Tensor& uvd) const;

  NetworkOptions options_;
  UNet unet_{nullptr};
  GlobalEncoder global_{nullptr};
  FieldMLP deformation_{nullptr}, shading_{nullptr};
};
TORCH_MODULE(ExpressionNetwork);

}  // namespace tega::nn
