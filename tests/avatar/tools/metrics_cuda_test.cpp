// CUDA-vs-CPU parity of the eval metrics: the same ATen ops in double on
// either device, so `tega eval --device cuda` reports what the CPU would.
// Skips where no CUDA device is present.

#include <ATen/ATen.h>
#include <ATen/Context.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "tega/tools/closeups.h"
#include "tega/tools/metrics.h"

namespace {

using namespace tega::tools;

TEST(MetricsCuda, MatchTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(3);
  // A render-sized image whose height and width are no multiple of a block,
  // a damaged copy (noise and a blurred band), and an irregular mask.
  const at::Tensor truth = at::rand({3, 333, 517});
  at::Tensor render = (truth + 0.05 * at::randn_like(truth)).clamp(0, 1);
  render.slice(1, 100, 200).copy_(at::avg_pool2d(truth.unsqueeze(0), 5, 1, 2).squeeze(0).slice(1, 100, 200));
  const at::Tensor mask = at::rand({333, 517}).gt(0.3);

  using Masked = std::function<double(const at::Tensor&, const at::Tensor&, const at::Tensor&)>;
  const std::vector<std::pair<std::string, Masked>> metrics = {
      {"psnr", [](const auto& a, const auto& b, const auto& m) { return psnr(a, b, m); }},
      {"ssim", [](const auto& a, const auto& b, const auto& m) { return ssim(a, b, m); }},
      {"l1", [](const auto& a, const auto& b, const auto& m) { return l1(a, b, m); }},
      {"hf_psnr", [](const auto& a, const auto& b, const auto& m) { return hf_psnr(a, b, m); }},
      {"gradient_error", [](const auto& a, const auto& b, const auto& m) { return gradient_error(a, b, m); }}};
  for (const auto& [name, metric] : metrics) {
    const double cpu = metric(render, truth, mask);
    const double gpu = metric(render.cuda(), truth.cuda(), mask.cuda());
    ASSERT_TRUE(std::isfinite(cpu)) << name;
    EXPECT_NEAR(gpu, cpu, 1e-9 * std::abs(cpu)) << name;
  }
}

// The close-ups average the same maps over boxes built on the images' device.
TEST(MetricsCuda, CloseupsMatchTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(4);
  const at::Tensor truth = at::rand({3, 240, 320});
  const at::Tensor render = (truth + 0.05 * at::randn_like(truth)).clamp(0, 1);
  const at::Tensor mask = at::rand({240, 320}).gt(0.2);
  // Eyes about (130, 100) and (190, 100), the mouth about (160, 170); the other landmarks at the centre.
  std::vector<std::optional<Eigen::Vector2d>> landmarks(kMarkupLandmarks, Eigen::Vector2d(160, 120));
  for (int i = 0; i < 6; ++i) {
    const double angle = M_PI * i / 3;
    landmarks[36 + i] = Eigen::Vector2d(130 + 12 * std::cos(angle), 100 + 4 * std::sin(angle));
    landmarks[42 + i] = Eigen::Vector2d(190 + 12 * std::cos(angle), 100 + 4 * std::sin(angle));
  }
  for (int i = 0; i < 20; ++i)
    landmarks[48 + i] = Eigen::Vector2d(160 + 20 * std::cos(M_PI * i / 10), 170 + 8 * std::sin(M_PI * i / 10));
  const auto cpu = closeup_metrics(error_maps(render, truth), mask, landmarks);
  const auto gpu = closeup_metrics(error_maps(render.cuda(), truth.cuda()), mask.cuda(), landmarks);
  ASSERT_EQ(cpu.size(), gpu.size());
  for (const auto& [name, value] : cpu) {
    ASSERT_TRUE(std::isfinite(value)) << name;
    EXPECT_NEAR(gpu.at(name), value, 1e-9 * std::abs(value)) << name;
  }
}

}  // namespace
