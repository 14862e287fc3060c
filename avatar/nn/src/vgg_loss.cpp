#include "tega/nn/vgg_loss.h"

#include <ATen/ATen.h>

#include <string>

#include "tega/core/error.h"
#include "tega/nn/safetensors.h"

namespace tega::nn {
namespace {

// Convolutions per block; a 2x2 max pool precedes every block but the first.
constexpr int kBlockConvs[] = {2, 2, 3, 3};

}  // namespace

const std::vector<int>& VggPerceptualLoss::conv_indices() {
  static const std::vector<int> indices{0, 2, 5, 7, 10, 12, 14, 17, 19, 21};
  return indices;
}

VggPerceptualLoss VggPerceptualLoss::load(const std::filesystem::path& file) {
  const SafetensorsFile contents = read_safetensors(file);
  VggPerceptualLoss loss;
  int64_t channels = 3;
  for (int index : conv_indices()) {
    const std::string prefix = "features." + std::to_string(index) + ".";
    const auto tensor = [&](const std::string& name) {
      const auto it = contents.tensors.find(prefix + name);
      if (it == contents.tensors.end()) throw Error(file, "missing VGG tensor '" + prefix + name + "'");
      if (!at::isFloatingType(it->second.scalar_type()))
        throw Error(file, "VGG tensor '" + prefix + name + "' is not floating point");
      return it->second.to(at::kFloat);
    };
    Conv conv{tensor("weight"), tensor("bias")};
    const at::Tensor& w = conv.weight;
    if (w.dim() != 4 || w.size(1) != channels || w.size(2) != 3 || w.size(3) != 3 || w.size(0) == 0)
      throw Error(file, "VGG tensor '" + prefix + "weight' has shape " + c10::str(w.sizes()) + ", expected [out, " +
                            std::to_string(channels) + ", 3, 3]");
    if (conv.bias.dim() != 1 || conv.bias.size(0) != w.size(0))
      throw Error(file, "VGG tensor '" + prefix + "bias' has shape " + c10::str(conv.bias.sizes()) + ", expected [" +
                            std::to_string(w.size(0)) + "]");
    channels = w.size(0);
    loss.convs_.push_back(std::move(conv));
  }
  loss.mean_ = at::tensor({0.485f, 0.456f, 0.406f}).view({1, 3, 1, 1});
  loss.std_ = at::tensor({0.229f, 0.224f, 0.225f}).view({1, 3, 1, 1});
  return loss;
}

std::vector<at::Tensor> VggPerceptualLoss::features(const at::Tensor& image) const {
  TORCH_CHECK((image.dim() == 3 || image.dim() == 4) && image.size(-3) == 3,
              "VGG loss takes [3,H,W] or [B,3,H,W] RGB images, got ", image.sizes());
  TORCH_CHECK(image.size(-1) >= 8 && image.size(-2) >= 8, "VGG loss needs images of at least 8x8 (three 2x2 pools)");
  at::Tensor h = ((image.dim() == 3 ? image.unsqueeze(0) : image) - mean_) / std_;
  std::vector<at::Tensor> out;
  size_t conv = 0;
  for (size_t block = 0; block < std::size(kBlockConvs); ++block) {
    if (block > 0) h = at::max_pool2d(h, {2, 2});
    for (int i = 0; i < kBlockConvs[block]; ++i, ++conv)
      h = at::relu(at::conv2d(h, convs_[conv].weight, convs_[conv].bias, /*stride=*/1, /*padding=*/1));
    out.push_back(h);
  }
  return out;
}

at::Tensor VggPerceptualLoss::operator()(const at::Tensor& rendered, const at::Tensor& target) const {
  TORCH_CHECK(rendered.sizes() == target.sizes(), "VGG loss: sizes differ, ", rendered.sizes(), " vs ",
              target.sizes());
  const std::vector<at::Tensor> a = features(rendered), b = features(target);
  at::Tensor total = (a[0] - b[0]).abs().mean();
  for (size_t i = 1; i < a.size(); ++i) total = total + (a[i] - b[i]).abs().mean();
  return total;
}

VggPerceptualLoss VggPerceptualLoss::to(const at::Device& device) const {
  VggPerceptualLoss moved;
  for (const auto& c : convs_) moved.convs_.push_back({c.weight.to(device), c.bias.to(device)});
  moved.mean_ = mean_.to(device);
  moved.std_ = std_.to(device);
  return moved;
}

}  // namespace tega::nn
