// sample_latent: the CUDA kernels against the CPU loops in double (values and
// gradients); skips where there is no GPU. The backward kernel sums runs of
// points that share taps before adding into the latent's gradient, so the
// cases cover points sorted by uv cell (long runs of one cell, a single
// texel), random order, channel counts on and off the warp's size, and uv on
// and beyond the texture's border.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <sstream>
#include <string>

#include "tega/nn/encoders.h"

namespace {

// (sampled, grad latent, grad uv) for the loss sum(sampled · weights).
std::vector<at::Tensor> run(const at::Tensor& latent_in, const at::Tensor& uv_in, const at::Tensor& weights,
                            const at::Device& device, at::ScalarType type) {
  const at::Tensor latent = latent_in.to(device, type).requires_grad_(true);
  const at::Tensor uv = uv_in.to(device, type).requires_grad_(true);
  const at::Tensor sampled = tega::nn::sample_latent(latent, uv);
  const auto g = torch::autograd::grad({(sampled * weights.to(device, type)).sum()}, {latent, uv});
  return {sampled.detach().cpu().to(at::kDouble), g[0].cpu().to(at::kDouble), g[1].cpu().to(at::kDouble)};
}

// Largest deviation within `tolerance` of the reference's largest magnitude:
// float sums in another order stay far below it, a lost or doubled run of
// points (a missed or repeated flush) does not.
void expect_near(const at::Tensor& gpu, const at::Tensor& reference, double tolerance, const std::string& what) {
  ASSERT_EQ(gpu.sizes(), reference.sizes()) << what;
  const double error = (gpu - reference).abs().max().item<double>();
  const double scale = reference.abs().max().item<double>();
  EXPECT_LE(error, tolerance * (1.0 + scale)) << what << ": largest |value| " << scale;
}

// Pixel coordinates (texel centres at integers) ≡ 1/128 modulo 1/64: the
// taps' cell and clamping are the same in float and double (no point on a
// kink of the uv gradient), yet points fill the cells densely.
at::Tensor snapped_texture_coordinate(int64_t count, int64_t size) {
  const at::Tensor pixel = at::rand({count}, at::kDouble) * (1.2 * size) - (0.1 * size + 0.5);
  return ((pixel * 64).floor() / 64 + 1.0 / 128 + 0.5) / size;
}

// Points over the texture and 10% beyond, with every third point's u, v or
// both on the border (0 or 1) or well beyond it.
at::Tensor points_with_border(int64_t count, int64_t height, int64_t width) {
  at::Tensor uv =
      at::stack({snapped_texture_coordinate(count, width), 1 - snapped_texture_coordinate(count, height)}, 1);
  const std::vector<double> border = {0.0, 1.0, -0.2, 1.3};
  auto a = uv.accessor<double, 2>();
  for (int64_t i = 0; i < count; i += 3) {
    const int64_t pick = (i / 3) % 3;
    if (pick != 1) a[i][0] = border[(i / 7) % border.size()];
    if (pick != 0) a[i][1] = border[(i / 5) % border.size()];
  }
  return uv.to(at::kFloat);
}

// The trainer's order: by uv cell (its top-left tap), row-major.
at::Tensor sorted_by_cell(const at::Tensor& uv, int64_t height, int64_t width) {
  const at::Tensor x = (uv.select(1, 0) * width - 0.5).clamp(0, double(width - 1)).floor();
  const at::Tensor y = ((1 - uv.select(1, 1)) * height - 0.5).clamp(0, double(height - 1)).floor();
  return uv.index_select(0, at::argsort(y * width + x));
}

void expect_matches_cpu(int64_t channels, int64_t height, int64_t width, int64_t points, bool sorted) {
  std::ostringstream name;
  name << channels << " channels, " << height << "x" << width << ", " << points << (sorted ? " sorted" : " random")
       << " points";
  const at::Tensor latent = at::randn({channels, height, width});
  at::Tensor uv = points_with_border(points, height, width);
  if (sorted) uv = sorted_by_cell(uv, height, width);
  const at::Tensor weights = at::randn({points, channels});
  const auto cpu = run(latent, uv, weights, at::kCPU, at::kDouble);
  const auto gpu = run(latent, uv, weights, at::Device(at::kCUDA, 0), at::kFloat);
  expect_near(gpu[0], cpu[0], 1e-5, "sampled, " + name.str());
  expect_near(gpu[1], cpu[1], 1e-5, "latent gradient, " + name.str());
  expect_near(gpu[2], cpu[2], 1e-5, "uv gradient, " + name.str());
}

TEST(SampleLatentCuda, MatchesTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(7);
  for (const bool sorted : {true, false}) {
    // The trainer's shape, smaller; ~200 points per cell when sorted.
    expect_matches_cpu(64, 16, 16, 50000, sorted);
    expect_matches_cpu(64, 64, 48, 20011, sorted);
    // Channels: 32 lanes with a partial second channel per lane; 3 and 4 per
    // lane (the latter in two chunks); groups of 8, 4, 2 and 1 lanes.
    expect_matches_cpu(40, 16, 24, 30000, sorted);
    expect_matches_cpu(96, 16, 16, 20000, sorted);
    expect_matches_cpu(200, 8, 8, 10000, sorted);
    expect_matches_cpu(8, 32, 32, 20000, sorted);
    expect_matches_cpu(5, 7, 11, 20003, sorted);
    expect_matches_cpu(3, 16, 16, 30000, sorted);
    expect_matches_cpu(2, 16, 16, 30000, sorted);
    expect_matches_cpu(1, 8, 8, 10001, sorted);
    // One texel (a global code: every point shares all four taps), one row.
    expect_matches_cpu(64, 1, 1, 20000, sorted);
    expect_matches_cpu(3, 1, 1, 5000, sorted);
    expect_matches_cpu(16, 1, 7, 5000, sorted);
  }
}

TEST(SampleLatentCuda, FewPoints) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(8);
  for (const int64_t points : {1, 2, 63, 65, 513}) {  // around a run of 64 points (8 groups: 512)
    expect_matches_cpu(64, 8, 8, points, false);
    expect_matches_cpu(3, 8, 8, points, true);
  }
}

}  // namespace
