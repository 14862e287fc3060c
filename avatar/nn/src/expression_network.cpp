#include "tega/nn/expression_network.h"

#include <ATen/ATen.h>

#include "tega/core/error.h"

namespace tega::nn {

ExpressionNetworkImpl::ExpressionNetworkImpl(const NetworkOptions& options) : options_(options) {
  const std::string source = "network options";
  if (options.latent_channels <= 0 || options.mlp_hidden <= 0 || options.pe_frequencies < 0 ||
      options.texture_size <= 0)
    throw Error(source + ": latent_channels, mlp_hidden and texture_size must be positive, pe_frequencies >= 0");
  int64_t condition_channels = options.latent_channels;
  if (options.latent == "unet") {
    if (options.unet_widths.empty()) throw Error(source + ": unet_widths is empty");
    const int factor = 1 << (options.unet_widths.size() - 1);
    if (options.texture_size % factor != 0)
      throw Error(source + ": texture_size " + std::to_string(options.texture_size) + " is not divisible by " +
                  std::to_string(factor) + " as " + std::to_string(options.unet_widths.size()) +
                  " U-Net levels need");
    UNetOptions u;
    u.latent_channels = options.latent_channels;
    u.widths.assign(options.unet_widths.begin(), options.unet_widths.end());
    u.input_scale = options.input_scale;
    unet_ = register_module("unet", UNet(u));
  } else if (options.latent == "global") {
    if (options.global_layers <= 0) throw Error(source + ": global_layers must be positive");
    GlobalEncoderOptions g;
    g.latent_channels = options.latent_channels;
    g.layers = options.global_layers;
    g.input_scale = options.input_scale;
    global_ = register_module("global", GlobalEncoder(g));
  } else if (options.latent == "none") {
    condition_channels = 0;
  } else {
    throw Error(source + ": latent must be unet, global or none, not '" + options.latent + "'");
  }

  FieldMLPOptions mlp;
  if (options.mlp_precision == "float32")
    mlp.precision = MlpPrecision::kFloat32;
  else if (options.mlp_precision == "bfloat16")
    mlp.precision = MlpPrecision::kBFloat16;
  else
    throw Error(source + ": mlp_precision must be float32 or bfloat16, not '" + options.mlp_precision + "'");
  mlp.fused = options.mlp_fused;
  mlp.condition_channels = condition_channels;
  mlp.hidden = options.mlp_hidden;
  mlp.encoding.frequencies = options.pe_frequencies;
  mlp.encoding.depth_scale = options.pe_depth_scale;
  mlp.outputs = 3;
  deformation_ = register_module("deformation", FieldMLP(mlp));
  mlp.outputs = 1;
  shading_ = register_module("shading", FieldMLP(mlp));
}

Latents ExpressionNetworkImpl::encode(const at::Tensor& displacement_texture) {
  const int64_t n = options_.texture_size;
  TORCH_CHECK(displacement_texture.dim() == 3 && displacement_texture.size(0) == 3 &&
                  displacement_texture.size(1) == n && displacement_texture.size(2) == n,
              "displacement texture must be [3,", n, ",", n, "], got ", displacement_texture.sizes());
  LatentPair pair;
  if (unet_)
    pair = unet_->forward(displacement_texture.unsqueeze(0));
  else if (global_)
    pair = global_->forward(displacement_texture.unsqueeze(0));
  else
    return {};
  return {pair.deformation.squeeze(0), pair.shading.squeeze(0)};
}

at::Tensor ExpressionNetworkImpl::condition(const at::Tensor& latent, const at::Tensor& uvd) const {
  if (options_.latent == "none") return {};
  TORCH_CHECK(latent.defined(), "latents are missing: call encode() first");
  return sample_latent(latent, uvd.narrow(1, 0, 2));
}

EncodedPositions ExpressionNetworkImpl::encode_positions(const at::Tensor& uvd, bool with_derivatives) const {
  // Both fields were built with the same encoding and precision options.
  return deformation_->encode(uvd, with_derivatives);
}

FieldWithJacobian ExpressionNetworkImpl::deform(const at::Tensor& uvd, const EncodedPositions& encoded,
                                                const Latents& latents, bool with_jacobian) {
  const at::Tensor f = condition(latents.deformation, uvd);
  if (with_jacobian) return deformation_->forward_with_jacobian(encoded, f);
  return {deformation_->forward(encoded, f), {}};
}

at::Tensor ExpressionNetworkImpl::shade(const at::Tensor& uvd, const EncodedPositions& encoded,
                                        const Latents& latents) {
  return 2 * at::sigmoid(shading_->forward(encoded, condition(latents.shading, uvd)).squeeze(1));
}

FieldWithJacobian ExpressionNetworkImpl::deform(const at::Tensor& uvd, const Latents& latents, bool with_jacobian) {
  return deform(uvd, encode_positions(uvd, with_jacobian), latents, with_jacobian);
}

at::Tensor ExpressionNetworkImpl::shade(const at::Tensor& uvd, const Latents& latents) {
  return shade(uvd, encode_positions(uvd, /*with_derivatives=*/false), latents);
}

}  // namespace tega::nn
