// shaded_sh against the tensor ops it replaces (scale, add, concatenate), value
// and gradients, at every SH degree's coefficient count.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "tega/trainer/spherical_harmonics.h"

namespace tega::trainer {
namespace {

struct Inputs {
  at::Tensor dc, rest, shading;
};

Inputs random_inputs(int64_t n, const at::TensorOptions& options, uint64_t seed) {
  at::manual_seed(seed);
  return {at::randn({n, 1, 3}, options), at::randn({n, 15, 3}, options), at::rand({n}, options) * 2 + 0.1};
}

at::Tensor composed(const Inputs& in, int used) {
  const at::Tensor s = in.shading.view({-1, 1, 1});
  const at::Tensor dc = in.dc * s + (0.5 / kShConstant) * (s - 1.0);
  return used > 1 ? at::cat({dc, in.rest.narrow(1, 0, used - 1) * s}, 1) : dc;
}

// Value and the gradients of all three inputs for one random upstream gradient.
std::vector<at::Tensor> evaluate(const Inputs& in, int used, bool fused, const at::Tensor& upstream) {
  const at::Tensor dc = in.dc.clone().requires_grad_(true), rest = in.rest.clone().requires_grad_(true),
                   shading = in.shading.clone().requires_grad_(true);
  const Inputs leaves{dc, rest, shading};
  const at::Tensor out = fused ? shaded_sh(dc, rest, shading, used) : composed(leaves, used);
  // The composed ops leave sh_rest out of the graph at one coefficient: its gradient is then zero.
  const auto grads = torch::autograd::grad({out}, {dc, rest, shading}, {upstream}, c10::nullopt, false, true);
  return {out.detach(), grads[0], grads[1].defined() ? grads[1] : at::zeros_like(rest), grads[2]};
}

TEST(ShadedSh, MatchesTheTensorOpsWithGradientsAtEveryDegree) {
  at::set_num_threads(2);
  const Inputs in = random_inputs(1001, at::kDouble, 3);
  for (const int used : {1, 4, 9, 16}) {
    SCOPED_TRACE(used);
    const at::Tensor upstream = at::randn({1001, used, 3}, at::kDouble);
    const auto expected = evaluate(in, used, false, upstream);
    const auto actual = evaluate(in, used, true, upstream);
    const char* names[] = {"value", "grad sh_dc", "grad sh_rest", "grad shading"};
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_TRUE(at::allclose(actual[i], expected[i], 1e-12, 1e-12)) << names[i];
    // Coefficients past `used` get no gradient.
    EXPECT_TRUE(actual[2].narrow(1, used - 1, 16 - used).eq(0).all().item<bool>());
  }
}

TEST(ShadedSh, RejectsMismatchedShapes) {
  const Inputs in = random_inputs(10, at::kFloat, 1);
  EXPECT_THROW(shaded_sh(in.dc, in.rest, in.shading, 17), c10::Error);
  EXPECT_THROW(shaded_sh(in.dc, in.rest.narrow(0, 0, 9), in.shading, 4), c10::Error);
  EXPECT_THROW(shaded_sh(in.dc, in.rest, in.shading.narrow(0, 0, 9), 4), c10::Error);
}

}  // namespace
}  // namespace tega::trainer
