#include "tega/tools/lpips.h"
#include <ATen/core/grad_mode.h>

#include <string>

#include "tega/core/error.h"
#include "tega/nn/safetensors.h"

namespace tega::tools {

namespace {

// VGG-16's five blocks up to relu5_3: convolutions per block (a 2x2 max pool
// precedes every block but the first), with torchvision's feature indices.
constexpr int kBlockConvs[] = {2, 2, 3, 3, 3};
constexpr int kConvIndices[] = {0, 2, 5, 7, 10, 12, 14, 17, 19, 21, 24, 26, 28};
constexpr double kEps = 1e-10;

at::Tensor float_tensor(const nn::SafetensorsFile& contents, const std::filesystem::path& file, const std::string& name) {
  const auto it = contents.tensors.find(name);
  if (it == contents.tensors.end()) throw Error(file, "missing LPIPS tensor '" + name + "'");
  if (!at::isFloatingType(it->second.scalar_type())) throw Error(file, "LPIPS tensor '" + name + "' is not floating point");
  return it->second.to(at::kFloat);
}

}  // namespace

Lpips Lpips::load(const std::filesystem::path& vgg_file, const std::filesystem::path& lin_file) {
  const nn::SafetensorsFile vgg = nn::read_safetensors(vgg_file);
  const nn::SafetensorsFile lin = lin_file == vgg_file ? vgg : nn::read_safetensors(lin_file);
  Lpips lpips;
  int64_t channels = 3;
  std::vector<int64_t> block_channels;
  size_t conv = 0;
  for (int block_convs : kBlockConvs) {
    for (int i = 0; i < block_convs; ++i, ++conv) {
      const std::string prefix = "features." + std::to_string(kConvIndices[conv]) + ".";
      Conv c{float_tensor(vgg, vgg_file, prefix + "weight"), float_tensor(vgg, vgg_file, prefix + "bias")};
      if (c.weight.dim() != 4 || c.weight.size(1) != channels || c.weight.size(2) != 3 || c.weight.size(3) != 3 ||
          c.weight.size(0) == 0)
        throw Error(vgg_file, "LPIPS tensor '" + prefix + "weight' has shape " + c10::str(c.weight.sizes()) +
                                  ", expected [out, " + std::to_string(channels) + ", 3, 3]");
      if (c.bias.dim() != 1 || c.bias.size(0) != c.weight.size(0))
        throw Error(vgg_file, "LPIPS tensor '" + prefix + "bias' has shape " + c10::str(c.bias.sizes()) + ", expected [" +
                                  std::to_string(c.weight.size(0)) + "]");
      channels = c.weight.size(0);
      lpips.convs_.push_back(std::move(c));
    }
    block_channels.push_back(channels);
  }
  for (size_t layer = 0; layer < block_channels.size(); ++layer) {
    const std::string name = "lin" + std::to_string(layer) + ".model.1.weight";
    at::Tensor w = float_tensor(lin, lin_file, name);
    if (w.dim() != 4 || w.size(0) != 1 || w.size(1) != block_channels[layer] || w.size(2) != 1 || w.size(3) != 1)
      throw Error(lin_file, "LPIPS tensor '" + name + "' has shape " + c10::str(w.sizes()) + ", expected [1, " +
                                std::to_string(block_channels[layer]) + ", 1, 1]");
    lpips.lin_.push_back(std::move(w));
  }
  lpips.shift_ = at::tensor({-0.030f, -0.088f, -0.188f}).view({1, 3, 1, 1});
  lpips.scale_ = at::tensor({0.458f, 0.448f, 0.450f}).view({1, 3, 1, 1});
  return lpips;
}

std::vector<at::Tensor> Lpips::features(const at::Tensor& image) const {
  at::Tensor h = (image.to(at::kFloat).unsqueeze(0) * 2.0 - 1.0 - shift_) / scale_;
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

double Lpips::operator()(const at::Tensor& a, const at::Tensor& b) const {
  TORCH_CHECK(a.dim() == 3 && a.size(0) == 3 && a.sizes() == b.sizes(), "LPIPS compares two RGB [3,H,W] images of one size, got ",
              a.sizes(), " and ", b.sizes());
  TORCH_CHECK(a.size(1) >= 16 && a.size(2) >= 16, "LPIPS needs images of at least 16x16 (four 2x2 pools)");
  at::NoGradGuard no_grad;
  const std::vector<at::Tensor> fa = features(a.to(shift_.device())), fb = features(b.to(shift_.device()));
  double total = 0;
  for (size_t layer = 0; layer < fa.size(); ++layer) {
    const auto unit = [](const at::Tensor& f) { return f / (f.square().sum(1, true).sqrt() + kEps); };
    const at::Tensor difference = (unit(fa[layer]) - unit(fb[layer])).square();
    total += at::conv2d(difference, lin_[layer]).mean().item<double>();
  }
  return total;
}

Lpips Lpips::to(const at::Device& device) const {
  Lpips moved;
  for (const auto& c : convs_) moved.convs_.push_back({c.weight.to(device), c.bias.to(device)});
  for (const auto& w : lin_) moved.lin_.push_back(w.to(device));
  moved.shift_ = shift_.to(device);
  moved.scale_ = scale_.to(device);
  return moved;
}

}  // namespace tega::tools
