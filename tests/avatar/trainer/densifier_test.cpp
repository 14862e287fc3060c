#include "tega/trainer/densifier.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/core/mesh.h"

namespace {

using namespace tega::trainer;

constexpr int64_t kLatentSide = 256;  // the trainer's default latent textures

// Two separate UV charts (triangles) with a gap between them.
tega::Mesh two_charts() {
  tega::Mesh m;
  m.positions.resize(6, 3);
  m.positions << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0.2, 0, 0, 0.3, 0, 0, 0.2, 0.1, 0;
  m.faces.resize(2, 3);
  m.faces << 0, 1, 2, 3, 4, 5;
  m.uvs.resize(6, 2);
  m.uvs << 0.05, 0.05, 0.45, 0.05, 0.05, 0.45, 0.55, 0.55, 0.95, 0.55, 0.55, 0.95;
  m.uv_faces = m.faces;
  m.triangle_polygon = {0, 1};
  return m;
}

DensifyStats stats_for(int64_t n, double gradient, double world_std) {
  DensifyStats s;
  s.reset(n, at::kCPU);
  s.gradient_norm_sum.fill_(gradient);
  s.visible_count.fill_(1);
  s.world_std.fill_(world_std);
  return s;
}

class DensifierTest : public ::testing::Test {
 protected:
  void SetUp() override {
    at::set_num_threads(2);
    gaussians = initialise_gaussians(lookup, 200, 0.25, false, kLatentSide, 3, at::TensorOptions(at::kFloat));
    for (const auto& name : Gaussians::parameter_names()) adam.add(name, gaussians.parameter(name), 1e-3);
  }
  tega::uvd::UvTriangleLookup lookup{two_charts(), {256, 0.1}};
  Gaussians gaussians;
  Adam adam;
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(5);
};

TEST_F(DensifierTest, SplitChildrenLandOnValidTrianglesAndShrink) {
  // Huge uv scales: children sampled from N(μ, Σ) fall far outside the charts.
  {
    at::NoGradGuard no_grad;
    gaussians.log_scale.fill_(std::log(0.3));
  }
  DensifyOptions options;
  const DensifyResult r = densify(gaussians, adam, stats_for(200, 1.0, 0.01), options, lookup, kLatentSide, generator);
  EXPECT_EQ(r.split, 200);
  EXPECT_EQ(r.cloned, 0);
  ASSERT_EQ(gaussians.size(), 400);
  const auto hit = lookup.lookup(gaussians.uvd.detach().slice(1, 0, 2));
  EXPECT_LT(hit.distance.max().item<double>(), 1e-6) << "a child lies outside every triangle";
  EXPECT_NEAR(gaussians.log_scale[0][0].item<float>(), std::log(0.3) - std::log(1.6), 1e-5);
  EXPECT_EQ(adam.group("uvd").first_moment.size(0), 400);
  EXPECT_TRUE(gaussians.uvd.requires_grad());
}

// Every Gaussian records the triangle it was created on; children that land
// on another triangle than their parent's record their own, so a count of
// Gaussians off their birth triangle sees only later motion.
TEST_F(DensifierTest, BirthTrianglesAreWhereEachGaussianWasCreated) {
  ASSERT_TRUE(gaussians.birth_triangle.defined());
  EXPECT_TRUE(at::equal(gaussians.birth_triangle, lookup.lookup(gaussians.uvd.detach().slice(1, 0, 2)).triangle));
  {
    at::NoGradGuard no_grad;
    gaussians.log_scale.fill_(std::log(0.3));  // children spread over the charts
  }
  densify(gaussians, adam, stats_for(200, 1.0, 0.01), DensifyOptions(), lookup, kLatentSide, generator);
  ASSERT_EQ(gaussians.birth_triangle.size(0), gaussians.size());
  EXPECT_TRUE(at::equal(gaussians.birth_triangle, lookup.lookup(gaussians.uvd.detach().slice(1, 0, 2)).triangle));
}

TEST_F(DensifierTest, SmallGaussiansAreClonedAndTransparentOnesPruned) {
  {
    at::NoGradGuard no_grad;
    gaussians.opacity_logit.slice(0, 0, 50).fill_(-10.0);  // opacity ~ 4.5e-5
  }
  DensifyOptions options;
  const DensifyResult r = densify(gaussians, adam, stats_for(200, 1.0, 1e-4), options, lookup, kLatentSide, generator);
  EXPECT_EQ(r.pruned, 50);
  EXPECT_EQ(r.cloned, 150);
  EXPECT_EQ(gaussians.size(), 300);
}

TEST_F(DensifierTest, NeverExceedsTheCapAndPrefersHighGradients) {
  DensifyStats stats = stats_for(200, 0.0, 1e-4);
  stats.gradient_norm_sum.slice(0, 0, 20).fill_(1.0);
  stats.gradient_norm_sum.slice(0, 20, 40).fill_(0.5);
  DensifyOptions options;
  options.max_gaussians = 210;
  densify(gaussians, adam, stats, options, lookup, kLatentSide, generator);
  EXPECT_EQ(gaussians.size(), 210);
}

TEST_F(DensifierTest, TriangleBindingChildrenInheritTheirTriangle) {
  gaussians = initialise_gaussians(lookup, 100, 0.25, true, kLatentSide, 3, at::TensorOptions(at::kFloat));
  adam = Adam();
  for (const auto& name : Gaussians::parameter_names()) adam.add(name, gaussians.parameter(name), 1e-3);
  {
    at::NoGradGuard no_grad;
    gaussians.log_scale.fill_(std::log(0.3));
  }
  const at::Tensor before = gaussians.bound_triangle.clone();
  densify(gaussians, adam, stats_for(100, 1.0, 0.01), DensifyOptions{}, lookup, kLatentSide, generator);
  ASSERT_EQ(gaussians.bound_triangle.size(0), 200);
  // Rows are re-sorted by uv afterwards, so compare how many Gaussians each triangle holds.
  EXPECT_TRUE(at::equal(at::bincount(gaussians.bound_triangle, {}, 2), 2 * at::bincount(before, {}, 2)));
}

TEST_F(DensifierTest, RowsStayInUvOrderWithTheirMoments) {
  adam.group("uvd").first_moment.copy_(gaussians.uvd.detach());  // a moment that identifies its row
  const DensifyResult r = densify(gaussians, adam, stats_for(200, 1.0, 1e-4), DensifyOptions{},
                                  lookup, kLatentSide, generator);
  ASSERT_EQ(r.cloned, 200);
  EXPECT_TRUE(at::equal(uv_order(gaussians.uvd, kLatentSide), at::arange(400, at::kLong)));
  // Originals kept their moments wherever they moved; clones start at zero.
  const at::Tensor m = adam.group("uvd").first_moment;
  const at::Tensor has_moment = m.abs().sum(1) > 0;
  EXPECT_EQ(has_moment.sum().item<int64_t>(), 200);
  EXPECT_TRUE(at::equal(m.index({has_moment}), gaussians.uvd.detach().index({has_moment})));
}

TEST_F(DensifierTest, WorldSizeIsClampedToTheLimits) {
  const at::Tensor factor = at::full({200, 3}, 0.25);
  {
    at::NoGradGuard no_grad;
    gaussians.log_scale.slice(0, 0, 100).fill_(std::log(1.0));   // 0.25 m: too large
    gaussians.log_scale.slice(0, 100, 200).fill_(std::log(1e-9));  // too small
  }
  clamp_world_size(gaussians, factor, 2e-5, 5e-3);
  const at::Tensor world = gaussians.log_scale.detach().exp() * factor;
  EXPECT_NEAR(world.max().item<double>(), 5e-3, 1e-8);
  EXPECT_NEAR(world.min().item<double>(), 2e-5, 1e-10);
}

// A checkpoint's triangle indices are checked as it loads: the GPU's uvd ->
// world reads its tables at them without a check of its own.
TEST_F(DensifierTest, CheckpointTensorsWithTrianglesOutsideTheTemplateAreRefused) {
  for (const bool bound : {true, false}) {
    const std::string name = bound ? "bound_triangle" : "birth_triangle";
    const Gaussians original = initialise_gaussians(lookup, 100, 0.25, bound, kLatentSide, 3,
                                                    at::TensorOptions(at::kFloat));
    std::map<std::string, at::Tensor> tensors = original.tensors();
    const Gaussians loaded = gaussians_from_tensors(tensors, at::kCPU, false, lookup.num_triangles());
    EXPECT_TRUE(at::equal(bound ? loaded.bound_triangle : loaded.birth_triangle, tensors.at("gaussians." + name)));

    tensors["gaussians." + name] = tensors.at("gaussians." + name).clone();
    tensors["gaussians." + name][7] = lookup.num_triangles();
    try {
      gaussians_from_tensors(tensors, at::kCPU, false, lookup.num_triangles());
      ADD_FAILURE() << name << " out of range was accepted";
    } catch (const tega::Error& e) {
      EXPECT_NE(std::string(e.what()).find("'gaussians." + name + "' holds triangle indices outside the template's 2"),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
