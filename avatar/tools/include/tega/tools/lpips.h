#pragma once
// LPIPS (Zhang et al. 2018), the "vgg" variant of the lpips package (v0.1):
//
//   x -> 2x - 1 -> (x - shift) / scale           shift (-.030, -.088, -.188), scale (.458, .448, .450)
//   VGG-16 features at relu1_2, relu2_2, relu3_3, relu4_3, relu5_3
//   per layer: unit-normalise over channels (x / (|x| + 1e-10)), square the
//   difference, weigh the channels by the learned 1x1 "lin" layer, average
//   over the image; LPIPS = the sum over the five layers.
//
// Weights come from two safetensors files (docs/render-eval-export.md has the
// conversion): torchvision's VGG-16 (features.0.weight ... features.28.bias)
// and the lpips package's linear layers (lin0.model.1.weight ... lin4, each
// [1, C, 1, 1]). Channel counts are whatever the files hold, as long as they
// chain, so tests can use tiny networks. One file holding both sets works too.

#include <ATen/ATen.h>

#include <filesystem>
#include <vector>

namespace tega::tools {

class Lpips {
 public:
  // Throws tega::Error naming the file and the tensor when one is missing or
  // has a shape that does not fit.
  static Lpips load(const std::filesystem::path& vgg_file, const std::filesystem::path& lin_file);

  // a, b: RGB [3,H,W] in [0,1], H and W at least 16 (four 2x2 pools).
  double operator()(const at::Tensor& a, const at::Tensor& b) const;

  Lpips to(const at::Device& device) const;

 private:
  struct Conv {
    at::Tensor weight, bias;
  };
  std::vector<Conv> convs_;     // torchvision indices 0, 2, 5, ..., 28 in order
  std::vector<at::Tensor> lin_;  // [1,C,1,1] per layer
  at::Tensor shift_, scale_;     // [1,3,1,1]

  std::vector<at::Tensor> features(const at::Tensor& image) const;
};

}  // namespace tega::tools
