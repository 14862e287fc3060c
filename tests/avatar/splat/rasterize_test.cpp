// CPU rasterizer: forward pass against the brute-force reference, culling,
// densification statistics and the scale/rotation helper.

#include "splat_test_scenes.h"

#include <ATen/Parallel.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

namespace tega::splat::test {
namespace {

class ReferenceTest : public ::testing::TestWithParam<SceneSpec> {
 protected:
  void SetUp() override { at::set_num_threads(2); }
};

TEST_P(ReferenceTest, ForwardMatchesBruteForce) {
  const Scene scene = random_scene(GetParam());
  const RasterOutput out = scene.render();
  const ReferenceImages ref = reference_render(scene);
  EXPECT_LT(max_abs_difference(to_vector(out.rgb), ref.rgb), 1e-5);
  EXPECT_LT(max_abs_difference(to_vector(out.alpha), ref.alpha), 1e-5);
  EXPECT_LT(max_abs_difference(to_vector(out.depth), ref.depth), 1e-5);
  // The scene must exercise blending, not just the background.
  EXPECT_GT(out.alpha.max().item<double>(), 0.5);
  EXPECT_GT(out.visible.sum().item<int64_t>(), scene.means.size(0));
}

SceneSpec spec(ColorMode colors, bool antialiased, uint64_t seed) {
  SceneSpec s;
  s.colors = colors;
  s.antialiased = antialiased;
  s.seed = seed;
  return s;
}

SceneSpec dense_spec() {
  // Hundreds of Gaussians per tile: several batches per tile, and pixels
  // that stop early on low transmittance.
  SceneSpec s;
  s.gaussians = 700;
  s.cameras = 2;
  s.width = 40;
  s.height = 33;
  s.spread = 0.3;
  s.min_scale = 0.02;
  s.max_scale = 0.1;
  s.max_opacity = 0.999;
  s.seed = 7;
  return s;
}

INSTANTIATE_TEST_SUITE_P(Scenes, ReferenceTest,
                         ::testing::Values(spec(ColorMode::kSh, false, 1), spec(ColorMode::kSh, true, 2),
                                           spec(ColorMode::kRgb, false, 3), spec(ColorMode::kPerCameraRgb, true, 4),
                                           dense_spec()));

TEST(Rasterize, FloatMatchesDouble) {
  at::set_num_threads(2);
  const Scene scene = random_scene(dense_spec());
  const RasterOutput d = scene.render();
  const RasterOutput f = scene.to(at::kFloat).render();
  EXPECT_LT(relative_error(f.rgb, d.rgb), 1e-5);
  EXPECT_LT(relative_error(f.alpha, d.alpha), 1e-5);
}

TEST(Rasterize, CullsGaussiansBehindOrOutsideTheImage) {
  SceneSpec s;
  s.gaussians = 3;
  s.cameras = 1;
  Scene scene = random_scene(s);
  const auto cam = scene.cameras[0];
  // Camera-space positions: in front and centred, far off to the side, behind.
  const double cam_points[3][3] = {{0.0, 0.0, 2.0}, {30.0, 0.0, 2.0}, {0.0, 0.0, -1.0}};
  for (int g = 0; g < 3; ++g)
    for (int k = 0; k < 3; ++k) {
      double world = 0;  // Rᵀ (p - t)
      for (int i = 0; i < 3; ++i) world += cam.rotation[3 * i + k] * (cam_points[g][i] - cam.translation[i]);
      scene.means[g][k] = world;
    }
  const RasterOutput out = scene.render();
  EXPECT_GT(out.radii[0][0].item<int>(), 0);
  EXPECT_EQ(out.radii[0][1].item<int>(), 0);
  EXPECT_EQ(out.radii[0][2].item<int>(), 0);
  EXPECT_TRUE(out.visible[0][0].item<bool>());
  EXPECT_FALSE(out.visible[0][2].item<bool>());
}

TEST(Rasterize, EmptyImageShowsTheBackground) {
  SceneSpec s;
  s.gaussians = 1;
  s.cameras = 1;
  Scene scene = random_scene(s);  // its only Gaussian sits behind camera 0
  const RasterOutput out = scene.render();
  EXPECT_EQ(out.alpha.abs().max().item<double>(), 0.0);
  EXPECT_EQ(out.depth.abs().max().item<double>(), 0.0);  // no weight to divide the depth by
  EXPECT_TRUE(at::allclose(out.rgb, scene.background.view({1, 1, 1, 3}).expand_as(out.rgb)));
}

// With R = I and a covariance flat in z, moving the mean along x or y moves
// only the 2D mean: |d loss / d mean2D| = |d loss / d mean_xy| · z / f.
TEST(Rasterize, AccumulatesMeanGradientNormsForDensification) {
  at::set_num_threads(1);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const double z = 2.0, focal = 40.0;
  RasterCamera cam;
  cam.translation = {0.0, 0.0, z};
  cam.fx = cam.fy = focal;
  cam.cx = 20;
  cam.cy = 15;
  RasterSettings settings;
  settings.width = 40;
  settings.height = 30;
  const at::Tensor means = at::tensor({0.05, -0.02, 0.0, 0.0, 0.0, -5.0}, opts).view({2, 3}).requires_grad_();
  const at::Tensor covs = at::tensor({0.01, 0.002, 0.0, 0.008, 0.0, 0.0, 0.01, 0.0, 0.0, 0.01, 0.0, 0.0}, opts).view({2, 6});
  const at::Tensor colors = at::tensor({0.9, 0.2, 0.4, 0.1, 0.1, 0.1}, opts).view({2, 3});
  const at::Tensor opacities = at::tensor({0.8, 0.8}, opts);
  const at::Tensor background = at::tensor({0.1, 0.3, 0.2}, opts);
  const at::Tensor target = at::rand({1, 30, 40, 3}, opts);
  MeanGradientStats stats = MeanGradientStats::zeros(means);
  double expected = 0;
  for (int call = 0; call < 2; ++call) {
    const RasterOutput out = rasterize(means, covs, colors, opacities, background, {cam}, settings, &stats);
    const at::Tensor loss = (out.rgb - target).abs().mean();
    const at::Tensor grad = torch::autograd::grad({loss}, {means})[0];
    expected += grad[0].slice(0, 0, 2).norm().item<double>() * z / focal;
  }
  EXPECT_NEAR(stats.grad_norm_sum[0].item<double>(), expected, 1e-9 * expected);
  EXPECT_GT(expected, 0.0);
  EXPECT_EQ(stats.visible_count[0].item<int>(), 2);
  EXPECT_EQ(stats.visible_count[1].item<int>(), 0);  // behind the camera
  EXPECT_EQ(stats.grad_norm_sum[1].item<double>(), 0.0);
}

TEST(Rasterize, CovarianceFromScaleRotation) {
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  // 90° about z (unnormalised quaternion): x -> y, so the x scale lands on y.
  const at::Tensor scales = at::tensor({1.0, 2.0, 3.0}, opts).view({1, 3});
  const at::Tensor quats = at::tensor({2.0, 0.0, 0.0, 2.0}, opts).view({1, 4});
  const at::Tensor cov = covariance_from_scale_rotation(scales, quats);
  const at::Tensor expected = at::tensor({4.0, 0.0, 0.0, 1.0, 0.0, 9.0}, opts).view({1, 6});
  EXPECT_TRUE(at::allclose(cov, expected, 1e-12, 1e-12)) << cov;
}

TEST(Rasterize, RejectsMismatchedInputs) {
  const Scene scene = random_scene(SceneSpec{});
  EXPECT_THROW(rasterize(scene.means, scene.covariances.slice(1, 0, 5), scene.colors, scene.opacities,
                         scene.background, scene.cameras, scene.settings),
               c10::Error);
  EXPECT_THROW(rasterize(scene.means, scene.covariances, scene.colors, scene.opacities.to(at::kFloat),
                         scene.background, scene.cameras, scene.settings),
               c10::Error);
  RasterSettings too_high = scene.settings;
  too_high.sh_degree = 4;
  EXPECT_THROW(rasterize(scene.means, scene.covariances, scene.colors, scene.opacities, scene.background,
                         scene.cameras, too_high),
               c10::Error);
}

}  // namespace
}  // namespace tega::splat::test
