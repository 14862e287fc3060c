#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tega/nn/losses.h"
#include "tega/tools/metrics.h"

namespace {

using namespace tega::tools;

at::Tensor test_image() {
  at::manual_seed(1);
  // Smooth content plus texture, in [0.1, 0.9] so that added noise is not clipped.
  const at::Tensor y = at::linspace(0, 1, 48).view({1, 48, 1}), x = at::linspace(0, 1, 64).view({1, 1, 64});
  const at::Tensor base = 0.5 + 0.25 * at::sin(6 * x + at::arange(3).view({3, 1, 1}).to(at::kFloat)) * at::cos(4 * y);
  return (base + 0.1 * (at::rand({3, 48, 64}) - 0.5)).clamp(0.1, 0.9);
}

TEST(Metrics, IdenticalImages) {
  const at::Tensor a = test_image();
  EXPECT_TRUE(std::isinf(psnr(a, a)) && psnr(a, a) > 0);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
  EXPECT_EQ(l1(a, a), 0.0);
  const at::Tensor mask = at::zeros({48, 64}, at::kBool);
  mask.slice(0, 10, 30).fill_(true);
  EXPECT_TRUE(std::isinf(psnr(a, a, mask)));
  EXPECT_NEAR(ssim(a, a, mask), 1.0, 1e-12);
  EXPECT_EQ(l1(a, a, mask), 0.0);
}

TEST(Metrics, KnownNoiseLevelGivesItsPsnr) {
  const at::Tensor a = test_image();
  // Exactly ±σ per value: the MSE is σ², so PSNR = -20 log10 σ.
  const double sigma = 0.05;
  const at::Tensor signs = at::rand({3, 48, 64}).gt(0.5).to(at::kFloat) * 2 - 1;
  const at::Tensor b = a + sigma * signs;
  EXPECT_NEAR(psnr(a, b), -20 * std::log10(sigma), 1e-4);  // 26.02 dB
  EXPECT_NEAR(l1(a, b), sigma, 1e-6);
  // Gaussian noise of σ = 0.02: 33.98 dB to within sampling error (the MSE
  // of 9216 samples has a relative std of sqrt(2/9216) = 1.5%, 0.064 dB).
  at::manual_seed(5);
  const at::Tensor c = a + 0.02 * at::randn({3, 48, 64});
  EXPECT_NEAR(psnr(a, c), -20 * std::log10(0.02), 0.3);
}

TEST(Metrics, SsimMatchesTheTrainingLossAndDropsWithNoise) {
  const at::Tensor a = test_image();
  at::manual_seed(2);
  const at::Tensor b = (a + 0.05 * at::randn({3, 48, 64})).clamp(0, 1);
  EXPECT_NEAR(ssim(a, b), tega::nn::ssim(a, b).item<double>(), 1e-5);
  EXPECT_LT(ssim(a, b), 0.95);
  EXPECT_GT(ssim(a, b), 0.0);
}

TEST(Metrics, MaskedMetricsSeeOnlyTheMask) {
  const at::Tensor a = test_image();
  at::Tensor b = a.clone();
  b.slice(1, 24).add_(0.1);  // damage only the bottom half
  const at::Tensor top = at::zeros({48, 64}, at::kBool), bottom = at::zeros({48, 64}, at::kBool);
  top.slice(0, 0, 24).fill_(true);
  bottom.slice(0, 24).fill_(true);
  EXPECT_TRUE(std::isinf(psnr(a, b, top)));
  EXPECT_NEAR(psnr(a, b, bottom), 20.0, 1e-4);
  EXPECT_NEAR(psnr(a, b), 20.0 + 10 * std::log10(2.0), 1e-4);  // half the pixels: MSE halves
  EXPECT_NEAR(l1(a, b, bottom), 0.1, 1e-6);
  EXPECT_NEAR(l1(a, b), 0.05, 1e-6);
  EXPECT_GT(ssim(a, b, top), ssim(a, b, bottom));
  EXPECT_TRUE(std::isnan(psnr(a, b, at::zeros({48, 64}, at::kBool))));  // an empty mask
}

TEST(Metrics, StatisticsHandleInfinityAndUndefinedValues) {
  const Statistics s = statistics({20.0, 22.0, 24.0});
  EXPECT_DOUBLE_EQ(s.mean, 22.0);
  EXPECT_NEAR(s.std, std::sqrt(8.0 / 3.0), 1e-12);
  EXPECT_EQ(s.count, 3);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const Statistics t = statistics({20.0, inf, nan});
  EXPECT_TRUE(std::isinf(t.mean));
  EXPECT_TRUE(std::isnan(t.std));
  EXPECT_EQ(t.count, 2);
  EXPECT_EQ(t.skipped, 1);
  EXPECT_EQ(statistics({nan}).count, 0);
}

}  // namespace
