#pragma once
// The perceptual term of TeGA §3.6 (Eq. 7): features of "the first four
// layers" of a pre-trained VGG. We read that as the four blocks of VGG-16
// that perceptual losses (and LPIPS) compare: ending at relu1_2, relu2_2,
// relu3_3 and relu4_3, i.e. torchvision's vgg16().features[0..22]:
//
//   block 1: conv 0, 2             (relu1_2)
//   block 2: pool, conv 5, 7       (relu2_2)
//   block 3: pool, conv 10, 12, 14 (relu3_3)
//   block 4: pool, conv 17, 19, 21 (relu4_3)
//
// all 3x3 convs with padding 1, each followed by ReLU; pools are 2x2 max.
// The loss is Σ_blocks mean |F_b(I) - F_b(Î)| after ImageNet normalisation
// (mean 0.485 0.456 0.406, std 0.229 0.224 0.225) of [0,1] RGB inputs.
//
// Weights come from a safetensors file with torchvision's key names
// (features.0.weight, features.0.bias, features.2.weight, ...); see
// docs/networks-and-losses.md for the conversion. Keys past features.21
// are ignored. Channel counts are whatever the file holds, as long as they
// chain (first conv takes 3 channels, each conv takes the previous one's
// outputs), so tests can use tiny networks.

#include <ATen/core/Tensor.h>

#include <filesystem>
#include <vector>

namespace tega::nn {

class VggPerceptualLoss {
 public:
  // The torchvision indices of the convolutions used, in order.
  static const std::vector<int>& conv_indices();

  // Throws tega::Error naming the file (and the tensor) if it is missing,
  // malformed, lacks a tensor, or has shapes that do not chain.
  static VggPerceptualLoss load(const std::filesystem::path& file);

  // rendered, target: [C=3,H,W] or [B,3,H,W] in [0,1]; H and W at least 8.
  // The weights are constants; gradients flow to `rendered` (and `target`).
  at::Tensor operator()(const at::Tensor& rendered, const at::Tensor& target) const;

  VggPerceptualLoss to(const at::Device& device) const;

 private:
  struct Conv {
    at::Tensor weight, bias;
  };
  std::vector<Conv> convs_;  // in conv_indices() order
  at::Tensor mean_, std_;    // [1,3,1,1]

  std::vector<at::Tensor> features(const at::Tensor& image) const;
};

}  // namespace tega::nn
