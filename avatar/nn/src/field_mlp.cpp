#include "tega/nn/field_mlp.h"

#include "tega/nn/silu_tangents.h"

#include "fused_field_mlp.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

namespace tega::nn {
namespace {

// w [rows, columns] with zero columns appended up to an aligned count, as a
// contiguous tensor: the first layer's weight slices then have the aligned
// rows of the encoding they multiply.
at::Tensor aligned_columns(const at::Tensor& w) {
  return at::constant_pad_nd(w, {0, aligned_width(w.size(1)) - w.size(1)});
}

}  // namespace

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

EncodedPositions FieldMLPImpl::encode(const at::Tensor& uvd, bool with_derivatives) const {
  return encode_positions(options_.encoding, uvd, layer_type(uvd), with_derivatives);
}

void FieldMLPImpl::check_encoded(const EncodedPositions& encoded, bool with_derivatives) const {
  const PositionalEncoding& pe = options_.encoding;
  TORCH_CHECK(encoded.encoding.defined() && encoded.encoding.dim() == 2 &&
                  encoded.encoding.size(1) == aligned_width(pe.channels()),
              "FieldMLP: the encoding must be [N,", aligned_width(pe.channels()), "] (encode_positions with ",
              pe.frequencies, " frequencies)");
  TORCH_CHECK(encoded.encoding.scalar_type() == layer_type(encoded.encoding),
              "FieldMLP: the encoding must be in the layers' type ", layer_type(encoded.encoding), ", got ",
              encoded.encoding.scalar_type());
  if (!with_derivatives) return;
  TORCH_CHECK(encoded.derivatives.defined() &&
                  encoded.derivatives.sizes().equals(
                      {3, encoded.encoding.size(0), aligned_width(pe.features())}) &&
                  encoded.derivatives.scalar_type() == encoded.encoding.scalar_type(),
              "FieldMLP: the Jacobian needs the encoding's derivatives (encode with with_derivatives)");
}

at::Tensor FieldMLPImpl::first_layer(const EncodedPositions& encoded, const at::Tensor& condition,
                                     const at::Tensor& weight) const {
  // The first layer's weight splits into its encoding and condition columns,
  // so [PE(uvd), f] is never concatenated in memory.
  const int64_t pe_channels = options_.encoding.channels(), points = encoded.encoding.size(0);
  const at::ScalarType type = weight.scalar_type();
  const at::Tensor encoded_part = at::addmm(input_->bias.to(type), encoded.encoding,
                                            aligned_columns(weight.narrow(1, 0, pe_channels)).t());
  if (options_.condition_channels == 0) {
    TORCH_CHECK(!condition.defined(), "this FieldMLP takes no condition");
    return encoded_part;
  }
  TORCH_CHECK(condition.defined() && condition.dim() == 2 && condition.size(0) == points &&
                  condition.size(1) == options_.condition_channels,
              "condition must be [N,", options_.condition_channels, "] for ", points, " points");
  return at::addmm(encoded_part, condition.to(type),
                   weight.narrow(1, pe_channels, options_.condition_channels).contiguous().t());
}

std::pair<at::Tensor, at::Tensor> FieldMLPImpl::output_layer(at::ScalarType type) const {
  const int64_t padding = aligned_width(options_.outputs) - options_.outputs;
  return {at::constant_pad_nd(output_->weight.to(type), {0, 0, 0, padding}),
          at::constant_pad_nd(output_->bias.to(type), {0, padding})};
}

bool FieldMLPImpl::runs_fused(const EncodedPositions& encoded) const {
  return options_.fused && options_.precision == MlpPrecision::kBFloat16 &&
         fused_field::supports(options_, encoded, input_->weight);
}

FieldWithJacobian FieldMLPImpl::fused_forward(const EncodedPositions& encoded, const at::Tensor& condition) const {
  if (options_.condition_channels == 0) {
    TORCH_CHECK(!condition.defined(), "this FieldMLP takes no condition");
  } else {
    TORCH_CHECK(condition.defined() && condition.dim() == 2 && condition.size(0) == encoded.encoding.size(0) &&
                    condition.size(1) == options_.condition_channels,
                "condition must be [N,", options_.condition_channels, "] for ", encoded.encoding.size(0), " points");
  }
  return fused_field::evaluate(
      options_, {input_->weight, input_->bias, hidden_->weight, hidden_->bias, output_->weight, output_->bias},
      encoded, condition);
}

at::Tensor FieldMLPImpl::forward(const at::Tensor& uvd, const at::Tensor& condition) {
  return forward(encode(uvd, /*with_derivatives=*/false), condition);
}

FieldWithJacobian FieldMLPImpl::forward_with_jacobian(const at::Tensor& uvd, const at::Tensor& condition) {
  return forward_with_jacobian(encode(uvd, /*with_derivatives=*/true), condition);
}

at::Tensor FieldMLPImpl::forward(const EncodedPositions& encoded, const at::Tensor& condition) {
  check_encoded(encoded, /*with_derivatives=*/false);
  if (runs_fused(encoded)) return fused_forward({encoded.encoding, at::Tensor()}, condition).value;
  const at::ScalarType type = encoded.encoding.scalar_type();
  at::Tensor h = at::silu(first_layer(encoded, condition, input_->weight.to(type)));
  h = at::silu(at::linear(h, hidden_->weight.to(type), hidden_->bias.to(type)));
  const auto [output_weight, output_bias] = output_layer(type);
  return at::linear(h, output_weight, output_bias)
      .narrow(1, 0, options_.outputs)
      .to(output_->weight.scalar_type())
      .contiguous();
}

FieldWithJacobian FieldMLPImpl::forward_with_jacobian(const EncodedPositions& encoded, const at::Tensor& condition) {
  // Tangents are stored as [N, 3 (uvd axis), channels], so a linear layer acts
  // on them as a right-multiplication by Wᵀ, like on the activations. In the
  // first layer, axis a's tangent only meets the encoding channels of axis a
  // (3f + a): one [N,features] x [features,hidden] product per axis. Three
  // plain products, not one batched one: cuBLAS computes the weight gradient
  // of a batched product with K = N as a slow batched GEMV (130 ms at 4M).
  check_encoded(encoded, /*with_derivatives=*/true);
  if (runs_fused(encoded)) return fused_forward(encoded, condition);
  const at::ScalarType type = encoded.encoding.scalar_type();
  const int64_t n = encoded.encoding.size(0), hidden = options_.hidden, features = options_.encoding.features();
  const at::Tensor input_weight = input_->weight.to(type), hidden_weight = hidden_->weight.to(type);
  const at::Tensor pe_weight = input_weight.narrow(1, 0, options_.encoding.channels()).view({hidden, features, 3});
  std::vector<at::Tensor> axes;
  for (int64_t a = 0; a < 3; ++a)
    axes.push_back(at::mm(encoded.derivatives[a], aligned_columns(pe_weight.select(2, a)).t()));
  SiluWithTangents layer = silu_with_tangents(first_layer(encoded, condition, input_weight), at::stack(axes, 1));
  const auto next_tangents = [&](const at::Tensor& weight) {
    return layer.tangents.reshape({n * 3, hidden}).matmul(weight.t()).view({n, 3, -1});
  };
  layer = silu_with_tangents(at::linear(layer.value, hidden_weight, hidden_->bias.to(type)),
                             next_tangents(hidden_weight));
  const auto [output_weight, output_bias] = output_layer(type);
  const at::ScalarType out = output_->weight.scalar_type();
  const int64_t outputs = options_.outputs;
  return {at::linear(layer.value, output_weight, output_bias).narrow(1, 0, outputs).to(out).contiguous(),
          next_tangents(output_weight).narrow(2, 0, outputs).transpose(1, 2).to(out).contiguous()};
}

}  // namespace tega::nn
