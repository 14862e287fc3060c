#include "tega/nn/field_mlp.h"

#include "tega/nn/silu_tangents.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <cmath>

namespace tega::nn {
namespace {

// Per-axis scale (1, 1, depth_scale), shaped to broadcast against [N,3].
// Filled on the device: a tensor built from host values would be a copy that
// waits for the GPU's queue at every call.
at::Tensor axis_scale(const at::Tensor& uvd, double depth_scale) {
  at::Tensor scale = at::ones({1, 3}, uvd.options().requires_grad(false));
  scale.narrow(1, 2, 1).fill_(depth_scale);
  return scale;
}

// π 2^k for k < frequencies, shaped [1,K,1].
at::Tensor octaves(int64_t frequencies, const at::TensorOptions& options) {
  return (at::pow(2.0, at::arange(frequencies, options)) * M_PI).view({1, -1, 1});
}

void check_uvd(const at::Tensor& uvd) {
  TORCH_CHECK(uvd.dim() == 2 && uvd.size(1) == 3, "uvd must be [N,3], got ", uvd.sizes());
}

}  // namespace

at::Tensor PositionalEncoding::encode(const at::Tensor& uvd) const {
  check_uvd(uvd);
  const at::Tensor x = uvd * axis_scale(uvd, depth_scale);
  const at::Tensor phase = x.unsqueeze(1) * octaves(frequencies, uvd.options());  // [N,K,3]
  const at::Tensor waves = at::stack({at::sin(phase), at::cos(phase)}, 2).view({uvd.size(0), 2 * frequencies, 3});
  return at::cat({x.unsqueeze(1), waves}, 1).view({uvd.size(0), channels()});
}

at::Tensor PositionalEncoding::axis_derivatives(const at::Tensor& uvd) const {
  check_uvd(uvd);
  const at::Tensor scale = axis_scale(uvd, depth_scale).t().unsqueeze(2);  // [3,1,1]
  const at::Tensor omega = octaves(frequencies, uvd.options()).view({1, 1, -1});
  const at::Tensor phase = (uvd.t().unsqueeze(2) * scale) * omega;  // [3,N,K]
  const at::Tensor rate = omega * scale;                            // [3,1,K]
  const at::Tensor waves = at::stack({rate * at::cos(phase), -rate * at::sin(phase)}, 3).view({3, uvd.size(0), -1});
  return at::cat({scale.expand({3, uvd.size(0), 1}), waves}, 2);
}

FieldMLPImpl::FieldMLPImpl(const FieldMLPOptions& options) : options_(options) {
  TORCH_CHECK(options.hidden > 0 && options.outputs > 0 && options.condition_channels >= 0,
              "FieldMLP needs positive widths");
  const int64_t in = options.encoding.channels() + options.condition_channels;
  input_ = register_module("input", torch::nn::Linear(in, options.hidden));
  hidden_ = register_module("hidden", torch::nn::Linear(options.hidden, options.hidden));
  output_ = register_module("output", torch::nn::Linear(options.hidden, options.outputs));
  // TeGA §3.7: a null initial field (deformation 0, shading 2·sigmoid(0) = 1).
  at::NoGradGuard no_grad;
  output_->weight.zero_();
  output_->bias.zero_();
}

at::ScalarType FieldMLPImpl::layer_type(const at::Tensor& uvd) const {
  if (uvd.is_cuda() && options_.precision == MlpPrecision::kBFloat16) return at::kBFloat16;
  return input_->weight.scalar_type();
}

at::Tensor FieldMLPImpl::first_layer(const at::Tensor& uvd, const at::Tensor& condition,
                                     const at::Tensor& weight) const {
  // The first layer's weight splits into its encoding and condition columns,
  // so [PE(uvd), f] is never concatenated in memory.
  const int64_t pe_channels = options_.encoding.channels();
  const at::ScalarType type = weight.scalar_type();
  const at::Tensor encoded = at::addmm(input_->bias.to(type), options_.encoding.encode(uvd).to(type),
                                       weight.narrow(1, 0, pe_channels).t());
  if (options_.condition_channels == 0) {
    TORCH_CHECK(!condition.defined(), "this FieldMLP takes no condition");
    return encoded;
  }
  TORCH_CHECK(condition.defined() && condition.dim() == 2 && condition.size(0) == uvd.size(0) &&
                  condition.size(1) == options_.condition_channels,
              "condition must be [N,", options_.condition_channels, "] for ", uvd.size(0), " points");
  return at::addmm(encoded, condition.to(type), weight.narrow(1, pe_channels, options_.condition_channels).t());
}

at::Tensor FieldMLPImpl::forward(const at::Tensor& uvd, const at::Tensor& condition) {
  const at::ScalarType type = layer_type(uvd);
  at::Tensor h = at::silu(first_layer(uvd, condition, input_->weight.to(type)));
  h = at::silu(at::linear(h, hidden_->weight.to(type), hidden_->bias.to(type)));
  return at::linear(h, output_->weight.to(type), output_->bias.to(type)).to(output_->weight.scalar_type());
}

FieldWithJacobian FieldMLPImpl::forward_with_jacobian(const at::Tensor& uvd, const at::Tensor& condition) {
  // Tangents are stored as [N, 3 (uvd axis), channels], so a linear layer acts
  // on them as a right-multiplication by Wᵀ, like on the activations. In the
  // first layer, axis a's tangent only meets the encoding channels of axis a
  // (3f + a): one [N,features] x [features,hidden] product per axis. Three
  // plain products, not one batched one: cuBLAS computes the weight gradient
  // of a batched product with K = N as a slow batched GEMV (130 ms at 4M).
  const at::ScalarType type = layer_type(uvd);
  const int64_t n = uvd.size(0), hidden = options_.hidden, features = options_.encoding.features();
  const at::Tensor input_weight = input_->weight.to(type), hidden_weight = hidden_->weight.to(type),
                   output_weight = output_->weight.to(type);
  const at::Tensor pe_weight = input_weight.narrow(1, 0, options_.encoding.channels()).view({hidden, features, 3});
  const at::Tensor derivatives = options_.encoding.axis_derivatives(uvd).to(type);  // [3,N,features]
  std::vector<at::Tensor> axes;
  for (int64_t a = 0; a < 3; ++a) axes.push_back(at::mm(derivatives[a], pe_weight.select(2, a).t()));
  SiluWithTangents layer = silu_with_tangents(first_layer(uvd, condition, input_weight), at::stack(axes, 1));
  const auto next_tangents = [&](const at::Tensor& weight) {
    return layer.tangents.reshape({n * 3, hidden}).matmul(weight.t()).view({n, 3, -1});
  };
  layer = silu_with_tangents(at::linear(layer.value, hidden_weight, hidden_->bias.to(type)),
                             next_tangents(hidden_weight));
  const at::ScalarType out = output_->weight.scalar_type();
  return {at::linear(layer.value, output_weight, output_->bias.to(type)).to(out),
          next_tangents(output_weight).transpose(1, 2).to(out)};
}

}  // namespace tega::nn
