#include "tega/nn/vgg_loss.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <map>

#include "tega/core/error.h"
#include "tega/nn/safetensors.h"
#include "test_support.h"

namespace tega::nn {
namespace {

// torchvision key names, tiny channel counts; out_channels[i] belongs to
// conv_indices()[i]. A key past features.21 must be ignored.
TensorMap tiny_vgg(const std::vector<int64_t>& out_channels) {
  TensorMap tensors;
  int64_t in = 3;
  for (size_t i = 0; i < out_channels.size(); ++i) {
    const std::string prefix = "features." + std::to_string(VggPerceptualLoss::conv_indices()[i]) + ".";
    tensors[prefix + "weight"] = at::randn({out_channels[i], in, 3, 3}) * 0.3;
    tensors[prefix + "bias"] = at::randn({out_channels[i]}) * 0.1;
    in = out_channels[i];
  }
  tensors["features.24.weight"] = at::randn({7, 1, 3, 3});
  return tensors;
}

const std::vector<int64_t> kTiny{2, 3, 3, 4, 2, 3, 2, 2, 3, 2};

// Expects load(file) to throw a tega::Error naming the file and `fragment`.
void expect_load_error(const std::filesystem::path& file, const std::string& fragment) {
  try {
    VggPerceptualLoss::load(file);
    ADD_FAILURE() << "no error for " << file;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

TEST(VggPerceptualLoss, ZeroForIdenticalImagesPositiveOtherwise) {
  test::TempDir dir;
  write_safetensors(dir / "vgg.safetensors", tiny_vgg(kTiny));
  const VggPerceptualLoss vgg = VggPerceptualLoss::load(dir / "vgg.safetensors");
  const at::Tensor image = at::rand({3, 16, 24});
  EXPECT_EQ(vgg(image, image).item<float>(), 0.0f);
  const at::Tensor rendered = (image + 0.1 * at::randn_like(image)).clamp(0, 1).requires_grad_(true);
  const at::Tensor loss = vgg(rendered, image);
  EXPECT_GT(loss.item<float>(), 0.0f);
  loss.backward();
  EXPECT_GT(rendered.grad().abs().sum().item<float>(), 0.0f);
}

// Identity convolutions (centre tap 1 per channel, zero bias) turn every
// block's features into the normalised image (pooled), which stays positive
// for pixels >= 0.5, so ReLU passes it. For constants 0.6 and 0.8 each block
// then contributes mean_c(0.2 / std_c): the loss checks the ImageNet
// normalisation, the four blocks and their L1 sum.
TEST(VggPerceptualLoss, IdentityWeightsExposeNormalisationAndBlocks) {
  test::TempDir dir;
  TensorMap tensors;
  at::Tensor identity = at::zeros({3, 3, 3, 3});
  for (int c = 0; c < 3; ++c) identity[c][c][1][1] = 1;
  for (int index : VggPerceptualLoss::conv_indices()) {
    tensors["features." + std::to_string(index) + ".weight"] = identity;
    tensors["features." + std::to_string(index) + ".bias"] = at::zeros({3});
  }
  write_safetensors(dir / "identity.safetensors", tensors);
  const VggPerceptualLoss vgg = VggPerceptualLoss::load(dir / "identity.safetensors");
  const float per_block = (0.2f / 0.229f + 0.2f / 0.224f + 0.2f / 0.225f) / 3;
  EXPECT_NEAR(vgg(at::full({2, 3, 16, 16}, 0.6f), at::full({2, 3, 16, 16}, 0.8f)).item<float>(), 4 * per_block,
              1e-4);
}

TEST(VggPerceptualLoss, MalformedWeightFilesNameFileAndTensor) {
  test::TempDir dir;
  expect_load_error(dir / "absent.safetensors", "cannot open");

  test::write_text(dir / "text.safetensors", "not a safetensors file at all");
  expect_load_error(dir / "text.safetensors", "header");

  TensorMap missing = tiny_vgg(kTiny);
  missing.erase("features.12.bias");
  write_safetensors(dir / "missing.safetensors", missing);
  expect_load_error(dir / "missing.safetensors", "features.12.bias");

  TensorMap broken_chain = tiny_vgg(kTiny);
  broken_chain["features.7.weight"] = at::randn({3, 5, 3, 3});  // features.5 outputs 3 channels, not 5
  write_safetensors(dir / "chain.safetensors", broken_chain);
  expect_load_error(dir / "chain.safetensors", "features.7.weight");

  TensorMap bad_bias = tiny_vgg(kTiny);
  bad_bias["features.0.bias"] = at::randn({3});
  write_safetensors(dir / "bias.safetensors", bad_bias);
  expect_load_error(dir / "bias.safetensors", "features.0.bias");

  TensorMap integer = tiny_vgg(kTiny);
  integer["features.2.weight"] = at::ones({3, 2, 3, 3}, at::kInt);
  write_safetensors(dir / "integer.safetensors", integer);
  expect_load_error(dir / "integer.safetensors", "features.2.weight");
}

}  // namespace
}  // namespace tega::nn
