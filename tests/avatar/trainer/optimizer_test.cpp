#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tega/splat/gaussian_math.h"
#include "tega/trainer/adam.h"
#include "tega/trainer/spherical_harmonics.h"

namespace {

using tega::trainer::Adam;

TEST(Adam, FirstStepMovesEachElementByTheLearningRate) {
  at::Tensor p = at::tensor({1.0, -2.0, 3.0}, at::kDouble).requires_grad_(true);
  Adam adam;
  adam.add("p", p, 0.1);
  (p * at::tensor({2.0, -5.0, 0.5}, at::kDouble)).sum().backward();
  adam.step();
  // Adam's first step is lr * sign(grad) (bias-corrected moments cancel).
  EXPECT_TRUE(at::allclose(p.detach(), at::tensor({0.9, -1.9, 2.9}, at::kDouble), 1e-9, 1e-9)) << p;
}

TEST(Adam, StepScaleGivesPerColumnStepSizes) {
  at::Tensor p = at::zeros({2, 3}, at::kDouble).requires_grad_(true);
  Adam adam;
  adam.add("p", p, 1.0, at::tensor({0.5, 0.5, 2.0}, at::kDouble).view({1, 3}));
  p.sum().backward();
  adam.step();
  EXPECT_TRUE(at::allclose(adam.group("p").parameter.detach()[0], at::tensor({-0.5, -0.5, -2.0}, at::kDouble)));
}

// The textbook update with tensor ops, for a few steps of random gradients.
TEST(Adam, MatchesTheTextbookUpdate) {
  at::manual_seed(3);
  for (const bool scaled : {false, true}) {
    SCOPED_TRACE(scaled ? "with a step scale" : "without a step scale");
    at::Tensor p = at::randn({50, 3}, at::kDouble).requires_grad_(true);
    const at::Tensor scale = at::tensor({0.5, 2.0, 1.5}, at::kDouble).view({1, 3});
    Adam adam(0.8, 0.95, 1e-8);
    adam.add("p", p, 0.01, scaled ? scale : at::Tensor());
    at::Tensor expected = p.detach().clone(), m = at::zeros_like(expected), v = at::zeros_like(expected);
    for (int t = 1; t <= 4; ++t) {
      const at::Tensor weights = at::randn({50, 3}, at::kDouble);
      p.mutable_grad() = at::Tensor();
      (p * weights).sum().backward();
      adam.step();
      m = 0.8 * m + 0.2 * weights;
      v = 0.95 * v + 0.05 * weights * weights;
      const at::Tensor m_hat = m / (1 - std::pow(0.8, t)), v_hat = v / (1 - std::pow(0.95, t));
      expected = expected - 0.01 * m_hat / (v_hat.sqrt() + 1e-8) * (scaled ? scale : at::ones_like(scale));
      EXPECT_TRUE(at::allclose(p.detach(), expected, 1e-12, 1e-12)) << "step " << t;
    }
  }
}

TEST(Adam, RejectsAStepScaleThatIsNotPerColumn) {
  at::Tensor p = at::zeros({2, 3}, at::kDouble).requires_grad_(true);
  Adam adam;
  adam.add("p", p, 1.0, at::ones({2, 1}, at::kDouble));
  p.sum().backward();
  EXPECT_THROW(adam.step(), c10::Error);
}

TEST(Adam, ReplaceRowsKeepsMomentsOfKeptRowsAndZeroesNewOnes) {
  at::Tensor p = at::arange(4, at::kDouble).view({4, 1}).requires_grad_(true);
  Adam adam;
  adam.add("p", p, 0.1);
  (p * at::tensor({1.0, 2.0, 3.0, 4.0}, at::kDouble).view({4, 1})).sum().backward();
  adam.step();
  const at::Tensor m_before = adam.group("p").first_moment.clone();
  const at::Tensor keep = at::tensor({3, 1}, at::kLong);
  at::Tensor next = at::cat({p.detach().index_select(0, keep), at::zeros({2, 1}, at::kDouble)}).requires_grad_(true);
  adam.replace_rows("p", next, keep, 2);
  const at::Tensor m = adam.group("p").first_moment;
  ASSERT_EQ(m.size(0), 4);
  EXPECT_DOUBLE_EQ(m[0].item<double>(), m_before[3].item<double>());
  EXPECT_DOUBLE_EQ(m[1].item<double>(), m_before[1].item<double>());
  EXPECT_DOUBLE_EQ(m[2].item<double>(), 0.0);
  EXPECT_TRUE(adam.group("p").parameter.is_same(next));
}

TEST(Adam, StateRoundTrips) {
  at::Tensor p = at::ones({3}, at::kDouble).requires_grad_(true);
  Adam a;
  a.add("p", p, 0.1);
  p.sum().backward();
  a.step();
  at::Tensor q = p.detach().clone().requires_grad_(true);
  Adam b;
  b.add("p", q, 0.1);
  b.load_state(a.state());
  EXPECT_EQ(b.steps(), 1);
  EXPECT_TRUE(at::equal(b.group("p").second_moment, a.group("p").second_moment));
}

TEST(SphericalHarmonics, DegreeZeroIsTheOffsetDcTerm) {
  const at::Tensor sh = at::zeros({2, 16, 3}, at::kDouble);
  sh.select(1, 0).fill_(1.0);
  const at::Tensor rgb = tega::trainer::sh_to_rgb(sh, at::randn({2, 3}, at::kDouble), 3);
  EXPECT_TRUE(at::allclose(rgb, at::full({2, 3}, 0.5 + 0.28209479177387814, at::kDouble)));
}

TEST(SphericalHarmonics, DegreeOneFollowsTheViewDirection) {
  // Coefficient 3 multiplies -c1 * x: looking along +x and -x gives opposite offsets.
  const at::Tensor sh = at::zeros({2, 4, 3}, at::kDouble);
  sh.select(1, 3).fill_(0.1);
  const at::Tensor dirs = at::tensor({2.0, 0.0, 0.0, -3.0, 0.0, 0.0}, at::kDouble).view({2, 3});
  const at::Tensor rgb = tega::trainer::sh_to_rgb(sh, dirs, 1);
  EXPECT_NEAR(rgb[0][0].item<double>(), 0.5 - 0.4886025119029199 * 0.1, 1e-12);
  EXPECT_NEAR(rgb[1][0].item<double>(), 0.5 + 0.4886025119029199 * 0.1, 1e-12);
}

TEST(SphericalHarmonics, MatchesTheRasterizersEvaluationAtEveryDegree) {
  const at::Tensor sh = at::randn({9, 16, 3}, at::kDouble) * 0.3;
  const at::Tensor dirs = at::randn({9, 3}, at::kDouble);
  for (int degree = 0; degree <= 3; ++degree) {
    const at::Tensor rgb = tega::trainer::sh_to_rgb(sh, dirs, degree);
    EXPECT_TRUE(at::allclose(tega::trainer::sh_to_rgb(sh.slice(1, 0, 1), sh.slice(1, 1), dirs, degree), rgb, 1e-14, 1e-14));
    for (int64_t i = 0; i < 9; ++i) {
      double expected[3];
      const at::Tensor row = sh[i].contiguous(), dir = dirs[i].contiguous();
      tega::splat::sh_to_rgb<double>(degree, row.data_ptr<double>(), dir.data_ptr<double>(), expected);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(rgb[i][ch].item<double>(), expected[ch], 1e-14) << "degree " << degree << ", Gaussian " << i;
    }
  }
}

}  // namespace
