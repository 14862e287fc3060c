// shaded_sh's CUDA kernels against the CPU loops, value and gradients, in
// double; skips where there is no GPU.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "tega/trainer/spherical_harmonics.h"

namespace tega::trainer {
namespace {

std::vector<at::Tensor> evaluate(const std::vector<at::Tensor>& inputs, int used, const at::Tensor& upstream,
                                 const at::Device& device) {
  std::vector<at::Tensor> leaves;
  for (const at::Tensor& t : inputs) leaves.push_back(t.to(device).requires_grad_(true));
  const at::Tensor out = shaded_sh(leaves[0], leaves[1], leaves[2], used);
  const auto grads = torch::autograd::grad({out}, leaves, {upstream.to(device)});
  return {out.detach().cpu(), grads[0].cpu(), grads[1].cpu(), grads[2].cpu()};
}

TEST(ShadedShCuda, MatchesTheCpuInDouble) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(5);
  const int64_t n = 100003;
  const std::vector<at::Tensor> inputs{at::randn({n, 1, 3}, at::kDouble), at::randn({n, 15, 3}, at::kDouble),
                                       at::rand({n}, at::kDouble) * 2 + 0.1};
  for (const int used : {1, 9, 16}) {
    SCOPED_TRACE(used);
    const at::Tensor upstream = at::randn({n, used, 3}, at::kDouble);
    const auto expected = evaluate(inputs, used, upstream, at::kCPU);
    const auto actual = evaluate(inputs, used, upstream, at::kCUDA);
    for (size_t i = 0; i < expected.size(); ++i) EXPECT_TRUE(at::allclose(actual[i], expected[i], 1e-12, 1e-12)) << i;
  }
}

}  // namespace
}  // namespace tega::trainer
