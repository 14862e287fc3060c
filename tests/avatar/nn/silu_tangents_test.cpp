// silu_with_tangents against the same function composed from tensor ops
// (values and gradients, in double), on the CPU.
#include "tega/nn/silu_tangents.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <string>

namespace {

using tega::nn::silu_with_tangents;

struct Composed {
  at::Tensor value, tangents;
};

Composed composed(const at::Tensor& pre, const at::Tensor& tangents) {
  const at::Tensor s = at::sigmoid(pre);
  return {pre * s, (s * (1 + pre * (1 - s))).unsqueeze(1) * tangents};
}

std::vector<at::Tensor> gradients(const at::Tensor& loss, const at::Tensor& pre, const at::Tensor& tangents) {
  return torch::autograd::grad({loss}, {pre, tangents}, {}, /*retain_graph=*/false, /*create_graph=*/false,
                               /*allow_unused=*/true);
}

class SiluTangents : public ::testing::Test {
 protected:
  at::Tensor pre = (at::randn({37, 9}, at::kDouble) * 3).requires_grad_(true);
  at::Tensor tangents = at::randn({37, 3, 9}, at::kDouble).requires_grad_(true);
  at::Tensor weight_value = at::randn({37, 9}, at::kDouble);
  at::Tensor weight_tangents = at::randn({37, 3, 9}, at::kDouble);
};

TEST_F(SiluTangents, ValuesMatchTheComposedOps) {
  const auto fused = silu_with_tangents(pre, tangents);
  const Composed reference = composed(pre, tangents);
  EXPECT_TRUE(at::allclose(fused.value, reference.value, 1e-14, 1e-14));
  EXPECT_TRUE(at::allclose(fused.tangents, reference.tangents, 1e-14, 1e-14));
}

TEST_F(SiluTangents, GradientsMatchAutogradThroughTheComposedOps) {
  const auto fused = silu_with_tangents(pre, tangents);
  const auto g = gradients((fused.value * weight_value).sum() + (fused.tangents * weight_tangents).sum(), pre, tangents);
  const Composed reference = composed(pre, tangents);
  const auto r = gradients((reference.value * weight_value).sum() + (reference.tangents * weight_tangents).sum(), pre,
                           tangents);
  EXPECT_TRUE(at::allclose(g[0], r[0], 1e-12, 1e-12));
  EXPECT_TRUE(at::allclose(g[1], r[1], 1e-12, 1e-12));
}

TEST_F(SiluTangents, GradientsWhenOnlyOneOutputIsUsed) {
  {
    const auto g = gradients((silu_with_tangents(pre, tangents).tangents * weight_tangents).sum(), pre, tangents);
    const auto r = gradients((composed(pre, tangents).tangents * weight_tangents).sum(), pre, tangents);
    EXPECT_TRUE(at::allclose(g[0], r[0], 1e-12, 1e-12));
    EXPECT_TRUE(at::allclose(g[1], r[1], 1e-12, 1e-12));
  }
  {
    const auto g = gradients((silu_with_tangents(pre, tangents).value * weight_value).sum(), pre, tangents);
    const auto r = gradients((composed(pre, tangents).value * weight_value).sum(), pre, tangents);
    EXPECT_TRUE(at::allclose(g[0], r[0], 1e-12, 1e-12));
    EXPECT_TRUE(!g[1].defined() || g[1].abs().max().item<double>() == 0.0);
  }
}

TEST_F(SiluTangents, FloatMatchesDouble) {
  const auto fused = silu_with_tangents(pre.detach().to(at::kFloat), tangents.detach().to(at::kFloat));
  const auto exact = silu_with_tangents(pre.detach(), tangents.detach());
  EXPECT_TRUE(at::allclose(fused.value.to(at::kDouble), exact.value, 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(fused.tangents.to(at::kDouble), exact.tangents, 1e-5, 1e-6));
}

TEST_F(SiluTangents, RejectsMismatchedShapes) {
  EXPECT_THROW(silu_with_tangents(pre, at::randn({37, 2, 9}, at::kDouble)), c10::Error);
  EXPECT_THROW(silu_with_tangents(pre, at::randn({37, 3, 8}, at::kDouble)), c10::Error);
  EXPECT_THROW(silu_with_tangents(pre, tangents.to(at::kFloat)), c10::Error);
}

// bfloat16 is for the CUDA kernels only (FieldMLP never sends it to the CPU).
TEST_F(SiluTangents, TheCpuRejectsBfloat16) {
  try {
    silu_with_tangents(pre.detach().to(at::kBFloat16), tangents.detach().to(at::kBFloat16));
    ADD_FAILURE() << "no error";
  } catch (const c10::Error& e) {
    EXPECT_NE(std::string(e.what()).find("float32 or float64"), std::string::npos) << e.what();
  }
}

}  // namespace
