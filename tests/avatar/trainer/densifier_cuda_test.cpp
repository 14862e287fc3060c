// Densification with the Gaussians on a GPU (the run's generator stays a CPU
// one); skips where there is none.
#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include "tega/trainer/densifier.h"

namespace {

using namespace tega::trainer;

constexpr int64_t kLatentSide = 256;  // the trainer's default latent textures

tega::Mesh one_chart() {
  tega::Mesh m;
  m.positions.resize(3, 3);
  m.positions << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0;
  m.faces.resize(1, 3);
  m.faces << 0, 1, 2;
  m.uvs.resize(3, 2);
  m.uvs << 0.05, 0.05, 0.95, 0.05, 0.05, 0.95;
  m.uv_faces = m.faces;
  m.triangle_polygon = {0};
  return m;
}

TEST(DensifierCuda, SplitsAndClonesOnTheGpuLikeOnTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const at::Device cuda(at::kCUDA, 0);
  const tega::uvd::UvTriangleLookup lookup = tega::uvd::UvTriangleLookup(one_chart(), {256, 0.1}).to(cuda);
  Gaussians g = initialise_gaussians(lookup, 100, 0.25, false, kLatentSide, 3,
                                     at::TensorOptions(at::kFloat).device(cuda));
  Adam adam;
  for (const auto& name : Gaussians::parameter_names()) adam.add(name, g.parameter(name), 1e-3);
  DensifyStats stats;
  stats.reset(100, cuda);
  stats.gradient_norm_sum.fill_(1.0);
  stats.visible_count.fill_(1);
  stats.world_std.slice(0, 0, 40).fill_(1e-2);  // split
  stats.world_std.slice(0, 40).fill_(1e-4);     // clone
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(5);

  const DensifyResult r = densify(g, adam, stats, DensifyOptions{}, lookup, kLatentSide, generator);
  EXPECT_EQ(r.split, 40);
  EXPECT_EQ(r.cloned, 60);
  ASSERT_EQ(g.size(), 60 + 60 + 80);
  EXPECT_TRUE(g.uvd.is_cuda());
  EXPECT_EQ(adam.group("uvd").first_moment.size(0), g.size());
  const auto hit = lookup.lookup(g.uvd.detach().slice(1, 0, 2));
  EXPECT_LT(hit.distance.max().item<double>(), 1e-6) << "a child lies outside the chart";
}

}  // namespace
