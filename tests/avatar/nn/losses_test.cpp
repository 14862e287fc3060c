#include "tega/nn/losses.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace tega::nn {
namespace {

TEST(L1Loss, IsTheMeanAbsoluteDifference) {
  const at::Tensor a = at::tensor({0.0f, 0.5f, 1.0f, 0.25f});
  const at::Tensor b = at::tensor({1.0f, 0.5f, 0.0f, 0.75f});
  EXPECT_FLOAT_EQ(l1_image_loss(a, b).item<float>(), (1 + 0 + 1 + 0.5f) / 4);
}

TEST(PyramidL1Loss, AveragesTheL1OfTheCoarserLevels) {
  // One channel, 4x4: level 1 is the 2x2 block means, level 2 the image mean.
  const at::Tensor a = at::arange(16, at::kFloat).reshape({1, 4, 4}) / 16;
  const at::Tensor b = at::zeros({1, 4, 4});
  const double level1 = (2.5 + 4.5 + 10.5 + 12.5) / 4 / 16;
  const double level2 = 7.5 / 16;
  EXPECT_NEAR(pyramid_l1_loss(a, b, 2).item<double>(), (level1 + level2) / 2, 1e-6);
  EXPECT_NEAR(pyramid_l1_loss(a, b, 1).item<double>(), level1, 1e-6);
}

TEST(PyramidL1Loss, SeesAMisalignmentButNotTextureFinerThanItsLevels) {
  // A 1-pixel checkerboard and its 1-pixel shift differ everywhere at full
  // resolution and nowhere in 2x2 means; a 16-pixel square moved by 4 pixels
  // differs at every level.
  const at::Tensor ramp = at::arange(32, at::kFloat);
  const at::Tensor checker = at::remainder(ramp.unsqueeze(1) + ramp.unsqueeze(0), 2).unsqueeze(0);
  const at::Tensor shifted = at::roll(checker, {1}, {2});
  EXPECT_FLOAT_EQ(l1_image_loss(checker, shifted).item<float>(), 1.0f);
  EXPECT_NEAR(pyramid_l1_loss(checker, shifted, 3).item<float>(), 0.0f, 1e-6);

  at::Tensor square = at::zeros({1, 32, 32});
  square.slice(1, 8, 24).slice(2, 8, 24).fill_(1);
  const at::Tensor moved = at::roll(square, {4}, {2});
  EXPECT_GT(pyramid_l1_loss(square, moved, 3).item<float>(), 0.05f);
}

TEST(PyramidL1Loss, NamesALevelTheImageCannotHave) {
  const at::Tensor a = at::zeros({3, 4, 4});
  EXPECT_NO_THROW(pyramid_l1_loss(a, a, 2));
  EXPECT_THROW(pyramid_l1_loss(a, a, 3), c10::Error);
  EXPECT_THROW(pyramid_l1_loss(a, a, 0), c10::Error);
}

TEST(Ssim, IsOneForIdenticalImages) {
  const at::Tensor image = at::rand({3, 24, 32});
  EXPECT_NEAR(ssim(image, image).item<float>(), 1.0f, 1e-5);
  EXPECT_NEAR(dssim_loss(image.unsqueeze(0), image.unsqueeze(0)).item<float>(), 0.0f, 1e-5);
}

TEST(Ssim, IsSymmetricAndDropsWithNoise) {
  const at::Tensor a = at::rand({1, 3, 32, 32});
  const at::Tensor slightly = (a + 0.02 * at::randn_like(a)).clamp(0, 1);
  const at::Tensor very = (a + 0.2 * at::randn_like(a)).clamp(0, 1);
  EXPECT_NEAR(ssim(a, very).item<float>(), ssim(very, a).item<float>(), 1e-6);
  EXPECT_GT(ssim(a, slightly).item<float>(), ssim(a, very).item<float>());
  EXPECT_LT(ssim(a, slightly).item<float>(), 1.0f);
}

// Two constant images c1, c2. With zero padding, the window mass inside the
// image at a pixel is w = wx·wy (1 in the interior), so mu = c w,
// var = c² w (1 - w), cov = c1 c2 w (1 - w): a closed form per pixel.
TEST(Ssim, MatchesTheClosedFormForConstantImages) {
  const int h = 14, w = 17;
  const double c1 = 0.3, c2 = 0.8, k1 = 1e-4, k2 = 9e-4;
  std::vector<double> g(11);
  double total = 0;
  for (int i = 0; i < 11; ++i) total += g[i] = std::exp(-(i - 5) * (i - 5) / (2 * 1.5 * 1.5));
  const auto mass = [&](int x, int n) {
    double m = 0;
    for (int i = 0; i < 11; ++i)
      if (x + i - 5 >= 0 && x + i - 5 < n) m += g[i] / total;
    return m;
  };
  double expected = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double m = mass(x, w) * mass(y, h);
      const double mu = (2 * c1 * c2 * m * m + k1) / ((c1 * c1 + c2 * c2) * m * m + k1);
      const double sigma = (2 * c1 * c2 * m * (1 - m) + k2) / ((c1 * c1 + c2 * c2) * m * (1 - m) + k2);
      expected += mu * sigma;
    }
  expected /= h * w;
  const at::Tensor a = at::full({2, h, w}, c1, at::kDouble);
  const at::Tensor b = at::full({2, h, w}, c2, at::kDouble);
  EXPECT_NEAR(ssim(a, b).item<double>(), expected, 1e-12);
}

TEST(DssimLoss, GradientMatchesFiniteDifferences) {
  const at::Tensor target = at::rand({1, 2, 9, 10}, at::kDouble);
  const at::Tensor rendered = at::rand({1, 2, 9, 10}, at::kDouble).requires_grad_(true);
  dssim_loss(rendered, target).backward();
  const at::Tensor grad = rendered.grad().view(-1);
  at::Tensor x = rendered.detach().clone();
  const at::Tensor flat = x.view(-1);
  const double h = 1e-6;
  for (int64_t i : {0, 17, 45, 92, 179}) {
    const double original = flat[i].item<double>();
    flat[i] = original + h;
    const double plus = dssim_loss(x, target).item<double>();
    flat[i] = original - h;
    const double minus = dssim_loss(x, target).item<double>();
    flat[i] = original;
    EXPECT_NEAR(grad[i].item<double>(), (plus - minus) / (2 * h), 1e-7) << "pixel " << i;
  }
}

TEST(JacobianSmoothness, NormalisationIsExplicit) {
  at::Tensor j = at::ones({2, 3, 3});
  j[1] *= 2;  // ‖J‖_F² = 9 and 36
  EXPECT_FLOAT_EQ(jacobian_smoothness_loss(j, Reduction::mean).item<float>(), 22.5f);
  EXPECT_FLOAT_EQ(jacobian_smoothness_loss(j, Reduction::sum).item<float>(), 45.0f);
}

TEST(JacobianSmoothness, SamplesCoverThePaperRange) {
  at::Generator generator = at::detail::createCPUGenerator(7);
  const at::Tensor uvd = sample_smoothness_uvd(20000, at::kFloat, generator);
  ASSERT_EQ(uvd.sizes(), (std::vector<int64_t>{20000, 3}));
  const at::Tensor lo = std::get<0>(uvd.min(0)), hi = std::get<0>(uvd.max(0));
  for (int k = 0; k < 2; ++k) {
    EXPECT_GE(lo[k].item<float>(), 0.0f);
    EXPECT_LT(lo[k].item<float>(), 0.01f);
    EXPECT_LE(hi[k].item<float>(), 1.0f);
    EXPECT_GT(hi[k].item<float>(), 0.99f);
  }
  EXPECT_GE(lo[2].item<float>(), -0.05f);
  EXPECT_LT(lo[2].item<float>(), -0.045f);
  EXPECT_LE(hi[2].item<float>(), 0.2f);
  EXPECT_GT(hi[2].item<float>(), 0.195f);
  // Same seed, same samples.
  at::Generator again = at::detail::createCPUGenerator(7);
  EXPECT_TRUE(at::equal(uvd, sample_smoothness_uvd(20000, at::kFloat, again)));
}

}  // namespace
}  // namespace tega::nn
