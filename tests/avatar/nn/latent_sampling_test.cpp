// sample_latent against grid_sample (align_corners=false, border padding),
// values and gradients, on the CPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "tega/nn/encoders.h"

namespace {

using tega::nn::sample_latent;

at::Tensor reference(const at::Tensor& latent, const at::Tensor& uv) {
  const at::Tensor grid = at::stack({uv.select(1, 0) * 2 - 1, 1 - uv.select(1, 1) * 2}, 1);
  constexpr int64_t kBilinear = 0, kBorder = 1;
  const at::Tensor sampled =
      at::grid_sampler(latent.unsqueeze(0), grid.view({1, 1, -1, 2}), kBilinear, kBorder, /*align_corners=*/false);
  return sampled.view({latent.size(0), uv.size(0)}).t();
}

void expect_same(int64_t channels, int64_t height, int64_t width, int64_t points) {
  const at::Tensor latent = at::randn({channels, height, width}, at::kDouble).requires_grad_(true);
  const at::Tensor uv = (at::rand({points, 2}, at::kDouble) * 1.2 - 0.1).requires_grad_(true);  // some outside [0,1]
  const at::Tensor weights = at::randn({points, channels}, at::kDouble);
  const at::Tensor ours = sample_latent(latent, uv), theirs = reference(latent, uv);
  ASSERT_EQ(ours.sizes(), theirs.sizes());
  EXPECT_TRUE(at::allclose(ours, theirs, 1e-12, 1e-12)) << channels << "x" << height << "x" << width;
  const auto g = torch::autograd::grad({(ours * weights).sum()}, {latent, uv});
  const auto r = torch::autograd::grad({(theirs * weights).sum()}, {latent, uv});
  EXPECT_TRUE(at::allclose(g[0], r[0], 1e-11, 1e-11)) << "latent gradient, " << channels << "x" << height << "x" << width;
  EXPECT_TRUE(at::allclose(g[1], r[1], 1e-10, 1e-10)) << "uv gradient, " << channels << "x" << height << "x" << width;
}

TEST(SampleLatent, MatchesGridSampleWithGradients) {
  expect_same(8, 16, 16, 200);
  expect_same(5, 7, 11, 150);   // channels that do not divide a warp, a non-square texture
  expect_same(64, 32, 32, 50);
}

TEST(SampleLatent, AGlobalCodeIsTheSameEverywhere) {
  const at::Tensor code = at::randn({6, 1, 1});
  const at::Tensor sampled = sample_latent(code, at::rand({9, 2}));
  EXPECT_TRUE(at::allclose(sampled, code.view({1, 6}).expand({9, 6})));
}

TEST(SampleLatent, RejectsBadShapes) {
  EXPECT_THROW(sample_latent(at::randn({6, 4}), at::rand({9, 2})), c10::Error);
  EXPECT_THROW(sample_latent(at::randn({6, 4, 4}), at::rand({9, 3})), c10::Error);
}

}  // namespace
