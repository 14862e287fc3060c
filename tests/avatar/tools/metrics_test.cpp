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

// A Gaussian blur (σ in pixels, edge-replicated) of a [C,H,W] image: the
// render that lost its fine detail.
at::Tensor blurred(const at::Tensor& image, double sigma) {
  const int64_t r = static_cast<int64_t>(std::ceil(3 * sigma));
  const at::Tensor x = at::arange(-r, r + 1, at::kDouble);
  at::Tensor g = at::exp(-x.square() / (2 * sigma * sigma));
  g = (g / g.sum()).to(image.scalar_type());
  const at::Tensor padded = at::replication_pad2d(image.unsqueeze(1), {r, r, r, r});
  return at::conv2d(at::conv2d(padded, g.view({1, 1, -1, 1})), g.view({1, 1, 1, -1})).squeeze(1);
}

at::Tensor full_mask() { return at::ones({48, 64}, at::kBool); }

TEST(Metrics, DetailMetricsOfIdenticalImagesAndOfAConstantOffset) {
  const at::Tensor a = test_image();
  EXPECT_EQ(gradient_error(a, a, full_mask()), 0.0);
  EXPECT_TRUE(std::isinf(hf_psnr(a, a, full_mask())) && hf_psnr(a, a, full_mask()) > 0);
  // A uniform brightness error is no detail error (the border is replicated,
  // not zero-padded, so it stays uniform up to the frame's edge). What is
  // left is the float32 rounding of a + 0.05 (~1e-9).
  const at::Tensor brighter = a + 0.05;
  EXPECT_NEAR(psnr(a, brighter, full_mask()), 26.02, 0.01);
  EXPECT_LT(gradient_error(a, brighter, full_mask()), 1e-7);
  EXPECT_GT(hf_psnr(a, brighter, full_mask()), 120.0);
}

TEST(Metrics, BlurScoresFarWorseOnDetailThanAShadingErrorOfEqualPsnr) {
  const at::Tensor truth = test_image();
  const at::Tensor mask = full_mask();
  const at::Tensor blurry = blurred(truth, 1.0);
  // A smooth shading error (one slow wave across the head) scaled to the
  // blurred render's masked MSE: plain PSNR cannot tell the two apart.
  const at::Tensor x = at::linspace(0, 1, 64).view({1, 1, 64}), y = at::linspace(0, 1, 48).view({1, 48, 1});
  const at::Tensor wave = at::sin(3.0 * x + 2.0 * y).expand({3, 48, 64});
  const double target_mse = (blurry - truth).square().mean().item<double>();
  const at::Tensor shaded = truth + wave * std::sqrt(target_mse / wave.square().mean().item<double>());
  ASSERT_NEAR(psnr(blurry, truth, mask), psnr(shaded, truth, mask), 1e-4);
  // Both 31.99 dB; HF PSNR 32.11 (blurry) against 73.47 dB, gradient error
  // 0.0080 against 0.0009.
  EXPECT_GT(hf_psnr(shaded, truth, mask) - hf_psnr(blurry, truth, mask), 15.0);
  EXPECT_GT(gradient_error(blurry, truth, mask), 5 * gradient_error(shaded, truth, mask));
  // The blur's error is nearly all detail: its HF-band PSNR is close to its
  // plain PSNR, and over the whole image not below it (the band's gain is at
  // most 1 at every frequency).
  EXPECT_GE(hf_psnr(blurry, truth, mask), psnr(blurry, truth, mask));
  EXPECT_LT(hf_psnr(blurry, truth, mask), psnr(blurry, truth, mask) + 2.0);
  // More blur, more detail lost, on both metrics.
  const at::Tensor blurrier = blurred(truth, 2.0);
  EXPECT_LT(hf_psnr(blurrier, truth, mask), hf_psnr(blurry, truth, mask));
  EXPECT_GT(gradient_error(blurrier, truth, mask), gradient_error(blurry, truth, mask));
}

TEST(Metrics, HfPsnrKeepsTheFinestDetailWhole) {
  // A ±d checkerboard error is all high frequency: the σ = 1.5 blur removes
  // it almost entirely, so its band PSNR is its plain PSNR, -20 log10 d.
  // Scored 5 px (the blur's radius) inside the frame, whose replicated
  // border breaks the pattern.
  const at::Tensor a = test_image();
  const at::Tensor parity = (at::arange(48).view({48, 1}) + at::arange(64).view({1, 64})).remainder(2);
  const at::Tensor checker = (parity.to(at::kFloat) * 2 - 1).expand({3, 48, 64});
  const at::Tensor inner = at::zeros({48, 64}, at::kBool);
  inner.slice(0, 5, 43).slice(1, 5, 59).fill_(true);
  const double d = 0.02;
  EXPECT_NEAR(hf_psnr(a, a + d * checker, inner), -20 * std::log10(d), 0.01);  // 33.98 dB
  EXPECT_NEAR(psnr(a, a + d * checker, inner), -20 * std::log10(d), 1e-4);
}

TEST(Metrics, GradientErrorOfAScaledStepEdge) {
  // A vertical step of height h between columns 19 and 20; the render's step
  // is k·h. The Sobel magnitude (kernels /8) of a step is h/2 on each of the
  // two columns beside it, on every row (the replicated border continues the
  // edge), and 0 elsewhere: the error is |k - 1|·h/2 on those two columns.
  const double h = 0.4, k = 0.25;
  const auto step = [](double height) {
    at::Tensor image = at::full({3, 48, 64}, 0.2);
    image.slice(2, 20).add_(height);
    return image;
  };
  const at::Tensor truth = step(h), render = step(k * h);
  const double per_edge_pixel = (1 - k) * h / 2;  // 0.15
  EXPECT_NEAR(gradient_error(render, truth, full_mask()), 2 * per_edge_pixel / 64, 1e-7);
  at::Tensor band = at::zeros({48, 64}, at::kBool);
  band.slice(1, 10, 30).fill_(true);  // 20 columns around the edge
  EXPECT_NEAR(gradient_error(render, truth, band), 2 * per_edge_pixel / 20, 1e-7);
  at::Tensor beside = at::zeros({48, 64}, at::kBool);
  beside.slice(1, 19, 20).fill_(true);
  EXPECT_NEAR(gradient_error(render, truth, beside), per_edge_pixel, 1e-7);
  // The magnitude has no sign: an edge stepping down by h scores as one stepping up.
  EXPECT_NEAR(gradient_error(step(-h), truth, full_mask()), 0.0, 1e-7);
}

TEST(Metrics, DetailMetricsSeeOnlyTheMask) {
  const at::Tensor a = test_image();
  at::Tensor b = a.clone();
  b.slice(1, 24).copy_(blurred(a, 1.5).slice(1, 24));  // blur only the bottom half
  // The top mask ends 6 rows above the damage, beyond both filters' reach (5 px).
  const at::Tensor top = at::zeros({48, 64}, at::kBool), bottom = at::zeros({48, 64}, at::kBool);
  top.slice(0, 0, 18).fill_(true);
  bottom.slice(0, 24).fill_(true);
  EXPECT_EQ(gradient_error(a, b, top), 0.0);
  EXPECT_TRUE(std::isinf(hf_psnr(a, b, top)));
  EXPECT_GT(gradient_error(a, b, bottom), 0.005);
  EXPECT_LT(hf_psnr(a, b, bottom), 40.0);
  // Over the whole image the same damage is spread over twice the pixels.
  EXPECT_LT(gradient_error(a, b, full_mask()), gradient_error(a, b, bottom));
  EXPECT_GT(hf_psnr(a, b, full_mask()), hf_psnr(a, b, bottom));
  EXPECT_TRUE(std::isnan(gradient_error(a, b, at::zeros({48, 64}, at::kBool))));  // an empty mask
  EXPECT_TRUE(std::isnan(hf_psnr(a, b, at::zeros({48, 64}, at::kBool))));
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
