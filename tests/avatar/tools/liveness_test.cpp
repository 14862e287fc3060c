// tega inspect's liveness figures on the tiny avatar: a perturbed network
// moves and shades Gaussians and every part gets a gradient; a field whose
// output layer is zero moves nothing; parts switched off are reported off;
// Gaussians off their birth triangle are counted.

#include "tega/tools/liveness.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tiny_avatar.h"

namespace tega::tools {
namespace {

double gradient_of(const Liveness& l, const std::string& part) {
  for (const auto& g : l.gradients)
    if (g.part == part) return g.mean_norm;
  ADD_FAILURE() << "no gradient reported for " << part;
  return std::nan("");
}

TEST(Liveness, PartsOfAPerturbedAvatarAreAliveAndReported) {
  test::TinyAvatar tiny;
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  EXPECT_TRUE(l.deformation);
  EXPECT_TRUE(l.shading);
  EXPECT_EQ(l.gaussians, 300);
  ASSERT_EQ(l.frames.size(), 2u);
  for (const auto& f : l.frames) {
    EXPECT_GT(f.deformation_mean_mm, 0.0) << f.frame;
    EXPECT_GE(f.deformation_p95_mm, f.deformation_mean_mm * 0.5) << f.frame;
    EXPECT_LT(f.shading_p01, f.shading_p99) << f.frame;
  }
  for (const char* part : {"gaussians.uvd", "gaussians.sh_dc", "network.encoder", "network.deformation",
                           "network.shading"})
    EXPECT_GT(gradient_of(l, part), 0.0) << part;
  EXPECT_FALSE(l.off_birth_triangle.has_value());
  const nlohmann::json j = liveness_json(l);
  EXPECT_EQ(j.at("frames").size(), 2u);
  EXPECT_NE(liveness_markdown(l, "tiny").find("deformation field: mean"), std::string::npos);
}

TEST(Liveness, AFieldWhoseOutputLayerIsZeroMovesNothing) {
  test::TinyAvatar tiny;
  {
    at::NoGradGuard no_grad;
    for (auto& item : tiny.model().network->named_parameters(true))
      if (item.key().rfind("deformation.output", 0) == 0) item.value().zero_();
  }
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  for (const auto& f : l.frames) {
    EXPECT_EQ(f.deformation_mean_mm, 0.0) << f.frame;
    EXPECT_EQ(f.deformation_p95_mm, 0.0) << f.frame;
  }
}

TEST(Liveness, PartsSwitchedOffAreReportedOff) {
  test::TinyAvatar tiny;
  tiny.avatar->phase.deformation = tiny.avatar->phase.shading = false;
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  EXPECT_FALSE(l.deformation);
  EXPECT_FALSE(l.shading);
  EXPECT_EQ(gradient_of(l, "network.deformation"), 0.0);
  EXPECT_EQ(gradient_of(l, "network.shading"), 0.0);
  EXPECT_GT(gradient_of(l, "gaussians.sh_dc"), 0.0);
  const std::string text = liveness_markdown(l, "off");
  EXPECT_NE(text.find("deformation field: off"), std::string::npos) << text;
  EXPECT_NE(text.find("dynamic shading: off"), std::string::npos) << text;
}

TEST(Liveness, CountsGaussiansOffTheirBirthTriangle) {
  test::TinyAvatar tiny;
  // Every Gaussian lies on the template's one triangle (0); say a third were born elsewhere.
  at::Tensor birth = at::zeros({300}, at::kLong);
  birth.slice(0, 0, 100).fill_(1);
  tiny.model().gaussians.birth_triangle = birth;
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  ASSERT_TRUE(l.off_birth_triangle.has_value());
  EXPECT_NEAR(*l.off_birth_triangle, 1.0 / 3.0, 1e-12);
}

}  // namespace
}  // namespace tega::tools
