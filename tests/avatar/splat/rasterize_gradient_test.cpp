// Gradients of the CPU rasterizer (double) against central finite
// differences, for every input element, on small random scenes.

#include "splat_test_scenes.h"

#include <ATen/Parallel.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <ATen/core/grad_mode.h>

#include <sstream>
#include <string>

namespace tega::splat::test {
namespace {

struct LossWeights {
  at::Tensor rgb, alpha, depth;
};

double weighted_loss(const RasterOutput& out, const LossWeights& w) {
  return ((out.rgb * w.rgb).sum() + (out.alpha * w.alpha).sum() + (out.depth * w.depth).sum()).item<double>();
}

// The scene with its inputs replaced by copies that require gradients, which
// go to `inputs` in Scene::inputs()'s order.
Scene with_differentiable_inputs(const Scene& scene, std::vector<at::Tensor>& inputs) {
  inputs = scene.inputs();
  for (at::Tensor& t : inputs) t = t.clone().requires_grad_();
  Scene differentiable = scene;
  differentiable.means = inputs[0];
  differentiable.covariances = inputs[1];
  differentiable.colors = inputs[2];
  differentiable.opacities = inputs[3];
  differentiable.background = inputs[4];
  return differentiable;
}

class GradientTest : public ::testing::TestWithParam<SceneSpec> {
 protected:
  void SetUp() override { at::set_num_threads(2); }
};

TEST_P(GradientTest, EveryInputMatchesFiniteDifferences) {
  Scene scene = random_scene(GetParam());
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const int64_t c = int64_t(scene.cameras.size()), h = scene.settings.height, w = scene.settings.width;
  const LossWeights weights{at::rand({c, h, w, 3}, opts) * 2 - 1, at::rand({c, h, w}, opts) * 2 - 1,
                            at::rand({c, h, w}, opts) * 2 - 1};

  std::vector<at::Tensor> inputs;
  const Scene differentiable = with_differentiable_inputs(scene, inputs);
  const RasterOutput out = differentiable.render();
  const at::Tensor loss = (out.rgb * weights.rgb).sum() + (out.alpha * weights.alpha).sum() +
                          (out.depth * weights.depth).sum();
  const std::vector<at::Tensor> grads = torch::autograd::grad({loss}, inputs);

  const at::NoGradGuard no_grad;
  const char* names[] = {"means", "covariances", "colors", "opacities", "background"};
  std::vector<at::Tensor*> targets = {&scene.means, &scene.covariances, &scene.colors, &scene.opacities,
                                      &scene.background};
  for (std::size_t i = 0; i < targets.size(); ++i) {
    at::Tensor& target = *targets[i];
    double* data = target.data_ptr<double>();
    const at::Tensor analytic = grads[i].contiguous();
    const double* a = analytic.data_ptr<double>();
    EXPECT_GT(analytic.abs().max().item<double>(), 1e-3) << names[i] << ": the scene must produce gradients";
    int failures = 0;
    std::ostringstream report;
    for (int64_t e = 0; e < target.numel(); ++e) {
      const double original = data[e];
      bool matched = false;
      double numeric = 0;
      // A second, smaller step tells a kink in the forward pass (an alpha
      // crossing 1/255 at one pixel) from a wrong gradient.
      for (double eps : {1e-6, 2.5e-7}) {
        data[e] = original + eps;
        const double plus = weighted_loss(scene.render(), weights);
        data[e] = original - eps;
        const double minus = weighted_loss(scene.render(), weights);
        data[e] = original;
        numeric = (plus - minus) / (2 * eps);
        if (std::abs(numeric - a[e]) <= 1e-5 + 1e-4 * std::abs(a[e])) {
          matched = true;
          break;
        }
      }
      if (!matched && failures++ < 5)
        report << "  " << names[i] << "[" << e << "]: analytic " << a[e] << ", numeric " << numeric << "\n";
    }
    EXPECT_EQ(failures, 0) << report.str();
  }
}

// Outputs the loss leaves out reach the backward pass as undefined gradients
// (the rasterizer skips their terms); the result must be that of zero weights.
TEST(Rasterize, OutputsLeftOutOfTheLossActAsZeroWeights) {
  SceneSpec s;
  s.seed = 15;
  const Scene scene = random_scene(s);
  const int64_t c = int64_t(scene.cameras.size()), h = scene.settings.height, w = scene.settings.width;
  const at::Tensor weight_rgb = at::rand({c, h, w, 3}, at::TensorOptions().dtype(at::kDouble)) * 2 - 1;
  const auto gradients = [&](bool zero_weighted_outputs) {
    std::vector<at::Tensor> inputs;
    const Scene differentiable = with_differentiable_inputs(scene, inputs);
    const RasterOutput out = differentiable.render();
    at::Tensor loss = (out.rgb * weight_rgb).sum();
    if (zero_weighted_outputs) loss = loss + (out.alpha * 0).sum() + (out.depth * 0).sum();
    return torch::autograd::grad({loss}, inputs);
  };
  const std::vector<at::Tensor> rgb_only = gradients(false), zero_weighted = gradients(true);
  for (std::size_t i = 0; i < rgb_only.size(); ++i) {
    EXPECT_GT(rgb_only[i].abs().max().item<double>(), 1e-3) << "input " << i;
    EXPECT_TRUE(at::allclose(rgb_only[i], zero_weighted[i], 1e-12, 1e-12)) << "input " << i;
  }
}

SceneSpec spec(ColorMode colors, bool antialiased, int sh_degree, uint64_t seed) {
  SceneSpec s;
  s.colors = colors;
  s.antialiased = antialiased;
  s.sh_degree = sh_degree;
  s.seed = seed;
  s.max_opacity = 0.999;  // some pixels reach the 0.99 alpha clamp
  return s;
}

INSTANTIATE_TEST_SUITE_P(Scenes, GradientTest,
                         ::testing::Values(spec(ColorMode::kSh, false, 3, 11), spec(ColorMode::kSh, true, 1, 12),
                                           spec(ColorMode::kRgb, true, 0, 13),
                                           spec(ColorMode::kPerCameraRgb, false, 0, 14)));

}  // namespace
}  // namespace tega::splat::test
