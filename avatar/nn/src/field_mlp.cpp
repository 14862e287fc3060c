#include "tega/nn/field_mlp.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <cmath>

namespace tega::nn {
namespace {

at::Tensor silu_derivative(const at::Tensor& x) {
  const at::Tensor s = at::sigmoid(x);
  return s * (1 + x * (1 - s));
}

// Per-axis scale (1, 1, depth_scale), shaped to broadcast against [N,3].
at::Tensor axis_scale(const at::Tensor& uvd, double depth_scale) {
  return at::tensor({1.0, 1.0, depth_scale}, uvd.options()).view({1, 3});
}

void check_uvd(const at::Tensor& uvd) {
  TORCH_CHECK(uvd.dim() == 2 && uvd.size(1) == 3, "uvd must be [N,3], got ", uvd.sizes());
}

}  // namespace

at::Tensor PositionalEncoding::encode(const at::Tensor& uvd) const {
  check_uvd(uvd);
  const at::Tensor x = uvd * axis_scale(uvd, depth_scale);
  std::vector<at::Tensor> parts{x};
  for (int64_t k = 0; k < frequencies; ++k) {
    const at::Tensor phase = x * (std::ldexp(M_PI, static_cast<int>(k)));
    parts.push_back(at::sin(phase));
    parts.push_back(at::cos(phase));
  }
  return at::cat(parts, 1);
}

at::Tensor PositionalEncoding::jacobian(const at::Tensor& uvd) const {
  check_uvd(uvd);
  // Each feature depends on one axis only, so every block is diagonal in
  // (axis, feature-of-that-axis); the blocks line up with encode()'s layout.
  const at::Tensor scale = axis_scale(uvd, depth_scale).expand_as(uvd);
  const at::Tensor x = uvd * scale;
  std::vector<at::Tensor> blocks{at::diag_embed(scale)};
  for (int64_t k = 0; k < frequencies; ++k) {
    const double omega = std::ldexp(M_PI, static_cast<int>(k));
    const at::Tensor phase = x * omega;
    blocks.push_back(at::diag_embed(omega * scale * at::cos(phase)));
    blocks.push_back(at::diag_embed(-omega * scale * at::sin(phase)));
  }
  return at::cat(blocks, 2);
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

at::Tensor FieldMLPImpl::first_layer_input(const at::Tensor& uvd, const at::Tensor& condition) const {
  const at::Tensor encoded = options_.encoding.encode(uvd);
  if (options_.condition_channels == 0) {
    TORCH_CHECK(!condition.defined(), "this FieldMLP takes no condition");
    return encoded;
  }
  TORCH_CHECK(condition.defined() && condition.dim() == 2 && condition.size(0) == uvd.size(0) &&
                  condition.size(1) == options_.condition_channels,
              "condition must be [N,", options_.condition_channels, "] for ", uvd.size(0), " points");
  return at::cat({encoded, condition}, 1);
}

at::Tensor FieldMLPImpl::forward(const at::Tensor& uvd, const at::Tensor& condition) {
  at::Tensor h = at::silu(input_->forward(first_layer_input(uvd, condition)));
  h = at::silu(hidden_->forward(h));
  return output_->forward(h);
}

FieldWithJacobian FieldMLPImpl::forward_with_jacobian(const at::Tensor& uvd, const at::Tensor& condition) {
  // Tangents are stored as [N, 3 (uvd axis), channels], so a linear layer acts
  // on them as a right-multiplication by Wᵀ, like on the activations.
  const int64_t pe_channels = options_.encoding.channels();
  at::Tensor pre = input_->forward(first_layer_input(uvd, condition));
  at::Tensor tangent = at::matmul(options_.encoding.jacobian(uvd), input_->weight.narrow(1, 0, pe_channels).t());
  tangent = silu_derivative(pre).unsqueeze(1) * tangent;
  at::Tensor h = at::silu(pre);

  pre = hidden_->forward(h);
  tangent = silu_derivative(pre).unsqueeze(1) * at::matmul(tangent, hidden_->weight.t());
  h = at::silu(pre);

  return {output_->forward(h), at::matmul(tangent, output_->weight.t()).transpose(1, 2)};
}

}  // namespace tega::nn
