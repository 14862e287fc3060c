// silu_with_tangents: the CUDA kernels against the CPU loops (values and
// gradients); skips where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "tega/nn/silu_tangents.h"

namespace {

struct Result {
  at::Tensor value, tangents, grad_pre, grad_tangents;
};

Result run(const at::Tensor& pre_in, const at::Tensor& tangents_in, const at::Tensor& weight_value,
           const at::Tensor& weight_tangents, const at::Device& device) {
  const at::Tensor pre = pre_in.to(device).requires_grad_(true);
  const at::Tensor tangents = tangents_in.to(device).requires_grad_(true);
  const auto out = tega::nn::silu_with_tangents(pre, tangents);
  const at::Tensor loss = (out.value * weight_value.to(device)).sum() + (out.tangents * weight_tangents.to(device)).sum();
  const auto g = torch::autograd::grad({loss}, {pre, tangents});
  return {out.value.detach().cpu(), out.tangents.detach().cpu(), g[0].cpu(), g[1].cpu()};
}

TEST(SiluTangentsCuda, MatchesTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  for (const int64_t rows : {1, 1000, 70001}) {
    const at::Tensor pre = at::randn({rows, 64}) * 3, tangents = at::randn({rows, 3, 64});
    const at::Tensor wv = at::randn({rows, 64}), wt = at::randn({rows, 3, 64});
    const Result cpu = run(pre, tangents, wv, wt, at::kCPU);
    const Result gpu = run(pre, tangents, wv, wt, at::Device(at::kCUDA, 0));
    EXPECT_TRUE(at::allclose(gpu.value, cpu.value, 1e-5, 1e-6)) << rows;
    EXPECT_TRUE(at::allclose(gpu.tangents, cpu.tangents, 1e-5, 1e-6)) << rows;
    EXPECT_TRUE(at::allclose(gpu.grad_pre, cpu.grad_pre, 1e-4, 1e-5)) << rows;
    EXPECT_TRUE(at::allclose(gpu.grad_tangents, cpu.grad_tangents, 1e-4, 1e-5)) << rows;
  }
}

}  // namespace
