#include "tega/nn/encoders.h"

#include <ATen/ATen.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/container/sequential.h>

#include <algorithm>

namespace tega::nn {
namespace {

constexpr double kLeakySlope = 0.2;

torch::nn::Sequential conv_block(int64_t in, int64_t out) {
  const auto leaky = torch::nn::LeakyReLUOptions().negative_slope(kLeakySlope);
  return torch::nn::Sequential(torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, 3).padding(1)),
                               torch::nn::LeakyReLU(leaky),
                               torch::nn::Conv2d(torch::nn::Conv2dOptions(out, out, 3).padding(1)),
                               torch::nn::LeakyReLU(leaky));
}

void check_texture(const at::Tensor& texture, int64_t channels) {
  TORCH_CHECK(texture.dim() == 4 && texture.size(1) == channels, "expected a [B,", channels,
              ",N,N] texture, got ", texture.sizes());
}

}  // namespace

UNetImpl::UNetImpl(const UNetOptions& options) : options_(options) {
  TORCH_CHECK(!options.widths.empty(), "the U-Net needs at least one level");
  down_ = register_module("down", torch::nn::ModuleList());
  up_ = register_module("up", torch::nn::ModuleList());
  int64_t in = options.in_channels;
  for (int64_t width : options.widths) {
    down_->push_back(conv_block(in, width));
    in = width;
  }
  for (size_t level = options.widths.size() - 1; level-- > 0;)
    up_->push_back(conv_block(options.widths[level + 1] + options.widths[level], options.widths[level]));
  deformation_head_ =
      register_module("deformation_head", torch::nn::Conv2d(torch::nn::Conv2dOptions(options.widths[0], options.latent_channels, 1)));
  shading_head_ =
      register_module("shading_head", torch::nn::Conv2d(torch::nn::Conv2dOptions(options.widths[0], options.latent_channels, 1)));
}

LatentPair UNetImpl::forward(const at::Tensor& texture) {
  check_texture(texture, options_.in_channels);
  const int64_t levels = static_cast<int64_t>(options_.widths.size());
  const int64_t factor = int64_t{1} << (levels - 1);
  TORCH_CHECK(texture.size(2) % factor == 0 && texture.size(3) % factor == 0, "U-Net with ", levels,
              " levels needs a texture size divisible by ", factor, ", got ", texture.sizes());

  std::vector<at::Tensor> skips;
  at::Tensor h = texture * options_.input_scale;
  for (int64_t level = 0; level < levels; ++level) {
    if (level > 0) h = at::avg_pool2d(h, {2, 2});
    h = down_[level]->as<torch::nn::Sequential>()->forward(h);
    skips.push_back(h);
  }
  for (int64_t i = 0; i + 1 < levels; ++i) {
    const at::Tensor& skip = skips[levels - 2 - i];
    h = at::upsample_nearest2d(h, at::IntArrayRef{skip.size(2), skip.size(3)});
    h = up_[i]->as<torch::nn::Sequential>()->forward(at::cat({h, skip}, 1));
  }
  return {deformation_head_->forward(h), shading_head_->forward(h)};
}

GlobalEncoderImpl::GlobalEncoderImpl(const GlobalEncoderOptions& options) : options_(options) {
  TORCH_CHECK(options.layers > 0, "the global encoder needs at least one layer");
  convs_ = register_module("convs", torch::nn::ModuleList());
  int64_t in = options.in_channels;
  for (int64_t i = 0; i < options.layers; ++i) {
    const int64_t out = std::min<int64_t>(int64_t{16} << std::min<int64_t>(i, 8), 256);
    convs_->push_back(torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, 3).stride(2).padding(1)));
    in = out;
  }
  deformation_head_ = register_module("deformation_head", torch::nn::Linear(in, options.latent_channels));
  shading_head_ = register_module("shading_head", torch::nn::Linear(in, options.latent_channels));
}

LatentPair GlobalEncoderImpl::forward(const at::Tensor& texture) {
  check_texture(texture, options_.in_channels);
  at::Tensor h = texture * options_.input_scale;
  for (const auto& conv : *convs_) h = at::leaky_relu(conv->as<torch::nn::Conv2d>()->forward(h), kLeakySlope);
  const at::Tensor pooled = h.mean({2, 3});
  return {deformation_head_->forward(pooled).unsqueeze(-1).unsqueeze(-1),
          shading_head_->forward(pooled).unsqueeze(-1).unsqueeze(-1)};
}

}  // namespace tega::nn
