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

}  // namespace
