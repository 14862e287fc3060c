#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tega/core/error.h"
#include "tega/nn/safetensors.h"
#include "tega/tools/lpips.h"
#include "test_support.h"

namespace {

using namespace tega;
using tega::tools::Lpips;

constexpr int kConvIndices[] = {0, 2, 5, 7, 10, 12, 14, 17, 19, 21, 24, 26, 28};

// Tiny VGG-16-shaped weights: 3 channels through block 1 (identity
// convolutions when `identity_block1`), then 2 channels; and LPIPS linear
// layers `lin` per block.
void write_weights(const std::filesystem::path& vgg, const std::filesystem::path& lin, bool identity_block1,
                   const std::vector<std::vector<float>>& lin_weights) {
  at::manual_seed(11);
  nn::TensorMap v;
  int64_t in = 3;
  for (int i = 0; i < 13; ++i) {
    const int64_t out = i < 2 ? 3 : 2;
    at::Tensor w = at::randn({out, in, 3, 3}) * 0.3;
    if (i < 2 && identity_block1) {
      w = at::zeros({3, 3, 3, 3});
      for (int c = 0; c < 3; ++c) w[c][c][1][1] = 1;
    }
    v["features." + std::to_string(kConvIndices[i]) + ".weight"] = w;
    v["features." + std::to_string(kConvIndices[i]) + ".bias"] = i < 2 && identity_block1 ? at::zeros({out}) : at::randn({out}) * 0.1;
    in = out;
  }
  nn::write_safetensors(vgg, v);
  nn::TensorMap l;
  for (int layer = 0; layer < 5; ++layer)
    l["lin" + std::to_string(layer) + ".model.1.weight"] =
        at::tensor(lin_weights[layer]).view({1, static_cast<int64_t>(lin_weights[layer].size()), 1, 1});
  nn::write_safetensors(lin, l);
}

at::Tensor constant_image(float r, float g, float b) {
  return at::tensor({r, g, b}).view({3, 1, 1}).expand({3, 16, 16}).contiguous();
}

TEST(Lpips, FirstLayerOfConstantImagesMatchesAHandComputation) {
  test::TempDir tmp;
  write_weights(tmp / "vgg.safetensors", tmp / "lin.safetensors", true, {{1, 1, 1}, {0, 0}, {0, 0}, {0, 0}, {0, 0}});
  const Lpips lpips = Lpips::load(tmp / "vgg.safetensors", tmp / "lin.safetensors");
  const float a[3] = {0.7f, 0.6f, 0.5f}, b[3] = {0.9f, 0.5f, 0.8f};
  // relu1_2 = the scaled input itself (identity convolutions, positive
  // values): unit-normalise over channels, square the difference, sum.
  const double shift[3] = {-0.030, -0.088, -0.188}, scale[3] = {0.458, 0.448, 0.450};
  double za[3], zb[3], na = 0, nb = 0;
  for (int c = 0; c < 3; ++c) {
    za[c] = (2 * a[c] - 1 - shift[c]) / scale[c];
    zb[c] = (2 * b[c] - 1 - shift[c]) / scale[c];
    ASSERT_GT(za[c], 0);
    ASSERT_GT(zb[c], 0);
    na += za[c] * za[c];
    nb += zb[c] * zb[c];
  }
  double expected = 0;
  for (int c = 0; c < 3; ++c) expected += std::pow(za[c] / std::sqrt(na) - zb[c] / std::sqrt(nb), 2);
  ASSERT_GT(expected, 0.01);
  EXPECT_NEAR(lpips(constant_image(a[0], a[1], a[2]), constant_image(b[0], b[1], b[2])), expected, 1e-5);
}

TEST(Lpips, IsZeroForIdenticalImagesAndSymmetric) {
  test::TempDir tmp;
  write_weights(tmp / "vgg.safetensors", tmp / "lin.safetensors", false,
                {{0.1f, 0.2f, 0.3f}, {0.5f, 0.1f}, {0.2f, 0.2f}, {0.3f, 0.1f}, {0.4f, 0.4f}});
  const Lpips lpips = Lpips::load(tmp / "vgg.safetensors", tmp / "lin.safetensors");
  at::manual_seed(4);
  const at::Tensor x = at::rand({3, 32, 32}), y = (x + 0.2 * at::randn({3, 32, 32})).clamp(0, 1);
  EXPECT_EQ(lpips(x, x), 0.0);
  EXPECT_GT(lpips(x, y), 1e-4);
  EXPECT_NEAR(lpips(x, y), lpips(y, x), 1e-7);
}

TEST(Lpips, MissingOrMisshapenWeightsNameTheFileAndTensor) {
  test::TempDir tmp;
  write_weights(tmp / "vgg.safetensors", tmp / "lin.safetensors", false, {{1, 1, 1}, {1, 1}, {1, 1}, {1, 1}, {1, 1, 1}});
  try {
    Lpips::load(tmp / "vgg.safetensors", tmp / "lin.safetensors");
    FAIL() << "a lin4 layer of the wrong width was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lin.safetensors"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lin4.model.1.weight"), std::string::npos) << e.what();
  }
  nn::write_safetensors(tmp / "empty.safetensors", {{"lin0.model.1.weight", at::ones({1, 3, 1, 1})}});
  try {
    Lpips::load(tmp / "vgg.safetensors", tmp / "empty.safetensors");
    FAIL() << "missing lin layers were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lin1.model.1.weight"), std::string::npos) << e.what();
  }
}

}  // namespace
