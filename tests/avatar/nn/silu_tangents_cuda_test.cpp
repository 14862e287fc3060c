// silu_with_tangents: the CUDA kernels against the CPU loops (values and
// gradients); skips where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/cuda.h>

#include "tega/nn/silu_tangents.h"
#include "../tensor_compare.h"

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

using tega::test::relative_error;

// The bfloat16 kernels (FieldMLP's mixed precision) against float64 on the
// CPU, both fed the same bfloat16-representable inputs and output weights:
// what is left is the rounding of the outputs to bfloat16, well under 1%.
TEST(SiluTangentsCuda, Bfloat16MatchesFloat64OnTheCpu) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const at::Device gpu(at::kCUDA, 0);
  const int64_t rows = 70001;
  const auto bf16_exact = [](const at::Tensor& t) { return t.to(at::kBFloat16).to(at::kDouble); };
  const at::Tensor pre = bf16_exact(at::randn({rows, 64}) * 3), tangents = bf16_exact(at::randn({rows, 3, 64}));
  const at::Tensor wv = bf16_exact(at::randn({rows, 64})), wt = bf16_exact(at::randn({rows, 3, 64}));
  for (const bool with_value : {true, false}) {  // without: the kernel's missing gradient of the activation
    const Result cpu = run(pre, tangents, with_value ? wv : at::zeros_like(wv), wt, at::kCPU);
    const at::Tensor p = pre.detach().to(gpu, at::kBFloat16).requires_grad_(true);
    const at::Tensor t = tangents.detach().to(gpu, at::kBFloat16).requires_grad_(true);
    const auto out = tega::nn::silu_with_tangents(p, t);
    ASSERT_EQ(out.value.scalar_type(), at::kBFloat16);
    ASSERT_EQ(out.tangents.scalar_type(), at::kBFloat16);
    at::Tensor loss = (out.tangents.to(at::kFloat) * wt.to(gpu, at::kFloat)).sum();
    if (with_value) loss = loss + (out.value.to(at::kFloat) * wv.to(gpu, at::kFloat)).sum();
    const auto g = torch::autograd::grad({loss}, {p, t});
    ASSERT_EQ(g[0].scalar_type(), at::kBFloat16);
    EXPECT_LE(relative_error(out.value.cpu(), cpu.value), 1e-2);
    EXPECT_LE(relative_error(out.tangents.cpu(), cpu.tangents), 1e-2);
    EXPECT_LE(relative_error(g[0].cpu(), cpu.grad_pre), 1e-2) << with_value;
    EXPECT_LE(relative_error(g[1].cpu(), cpu.grad_tangents), 1e-2) << with_value;
  }
}

}  // namespace
