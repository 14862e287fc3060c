// CUDA-vs-CPU parity: the CUDA pipeline (float) against the CPU pipeline in
// double on the same inputs, forward outputs and every gradient. Skips
// where no CUDA device is present.

#include "splat_test_scenes.h"

#include <ATen/Context.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

namespace tega::splat::test {
namespace {

struct RenderRun {
  RasterOutput out;
  std::vector<at::Tensor> grads;
  MeanGradientStats stats;
};

RenderRun render_with_grads(const Scene& scene, const at::Tensor& weight_rgb, const at::Tensor& weight_alpha,
                      const at::Tensor& weight_depth) {
  Scene s = scene;
  for (at::Tensor* t : {&s.means, &s.covariances, &s.colors, &s.opacities, &s.background}) t->requires_grad_();
  RenderRun run;
  run.stats = MeanGradientStats::zeros(s.means);
  run.out = s.render(&run.stats);
  const auto device = s.means.device();
  at::Tensor loss = (run.out.rgb * weight_rgb.to(device, run.out.rgb.scalar_type())).sum() +
                    (run.out.alpha * weight_alpha.to(device, run.out.alpha.scalar_type())).sum();
  // Without depth in the loss, the CUDA backward runs its depth-free variant.
  if (weight_depth.defined()) loss = loss + (run.out.depth * weight_depth.to(device, run.out.depth.scalar_type())).sum();
  run.grads = torch::autograd::grad({loss}, s.inputs());
  return run;
}

class CudaParityTest : public ::testing::TestWithParam<SceneSpec> {
 protected:
  void SetUp() override {
    if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
    at::set_num_threads(4);
  }
};

void expect_cuda_matches_cpu(const Scene& scene, bool depth_in_loss) {
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const int64_t c = int64_t(scene.cameras.size()), h = scene.settings.height, w = scene.settings.width;
  const at::Tensor weight_rgb = at::rand({c, h, w, 3}, opts) * 2 - 1;
  const at::Tensor weight_alpha = at::rand({c, h, w}, opts) * 2 - 1;
  const at::Tensor weight_depth = depth_in_loss ? (at::rand({c, h, w}, opts) * 2 - 1) * 0.1 : at::Tensor();

  const RenderRun cpu = render_with_grads(scene.to(at::kDouble), weight_rgb, weight_alpha, weight_depth);
  const RenderRun gpu = render_with_grads(scene.to(at::kFloat, at::kCUDA), weight_rgb, weight_alpha, weight_depth);

  EXPECT_LT(relative_error(gpu.out.rgb, cpu.out.rgb), 1e-4);
  EXPECT_LT(relative_error(gpu.out.alpha, cpu.out.alpha), 1e-4);
  EXPECT_LT(relative_error(gpu.out.depth, cpu.out.depth), 1e-4);
  const double radii_mismatch = (gpu.out.radii.cpu() != cpu.out.radii).to(at::kDouble).mean().item<double>();
  EXPECT_LT(radii_mismatch, 0.02);  // a radius on a rounding boundary may differ by one pixel
  EXPECT_TRUE(at::equal(gpu.out.visible.cpu(), cpu.out.visible));
  const char* names[] = {"means", "covariances", "colors", "opacities", "background"};
  for (std::size_t i = 0; i < cpu.grads.size(); ++i)
    EXPECT_LT(relative_error(gpu.grads[i], cpu.grads[i]), 1e-3) << names[i];
  EXPECT_LT(relative_error(gpu.stats.grad_norm_sum, cpu.stats.grad_norm_sum), 1e-3);
  EXPECT_TRUE(at::equal(gpu.stats.visible_count.cpu(), cpu.stats.visible_count));
}

// Float inputs, so that both pipelines see exactly the same values.
TEST_P(CudaParityTest, MatchesCpuInDouble) {
  expect_cuda_matches_cpu(random_scene(GetParam()).to(at::kFloat), /*depth_in_loss=*/true);
}

TEST_P(CudaParityTest, MatchesCpuInDoubleWithoutDepthInTheLoss) {
  expect_cuda_matches_cpu(random_scene(GetParam()).to(at::kFloat), /*depth_in_loss=*/false);
}

SceneSpec parity_spec(ColorMode colors, bool antialiased, uint64_t seed) {
  SceneSpec s;
  s.colors = colors;
  s.antialiased = antialiased;
  s.max_opacity = 0.999;
  s.seed = seed;
  return s;
}

// Thousands of Gaussians per tile: many 256-splat batches per tile in both
// passes, and pixels that stop early.
SceneSpec crowded_spec(bool antialiased) {
  SceneSpec s;
  s.gaussians = 6000;
  s.cameras = 2;
  s.width = 83;
  s.height = 61;
  s.spread = 0.35;
  s.min_scale = 0.01;
  s.max_scale = 0.08;
  s.max_opacity = 0.9;
  s.antialiased = antialiased;
  s.seed = 21;
  return s;
}

INSTANTIATE_TEST_SUITE_P(Scenes, CudaParityTest,
                         ::testing::Values(parity_spec(ColorMode::kSh, false, 1), parity_spec(ColorMode::kSh, true, 2),
                                           parity_spec(ColorMode::kRgb, false, 3), parity_spec(ColorMode::kPerCameraRgb, true, 4),
                                           crowded_spec(false), crowded_spec(true)));

}  // namespace
}  // namespace tega::splat::test
