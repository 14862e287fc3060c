// CUDA-vs-CPU parity of the fused SSIM: the CUDA kernels (float) against the
// CPU path in double on the same float images, value and gradient. Skips
// where no CUDA device is present.

#include "tega/nn/fused_ssim.h"

#include <ATen/ATen.h>
#include <ATen/Context.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <cmath>
#include <vector>
#include "../tensor_compare.h"

namespace tega::nn {
namespace {

using Shape = std::vector<int64_t>;

using test::relative_error;

// The largest difference relative to the largest reference value: catches a
// wrong border that a norm over a large image would average away.
double max_error(const at::Tensor& a, const at::Tensor& b) {
  const at::Tensor ad = a.detach().to(at::kCPU, at::kDouble), bd = b.detach().to(at::kCPU, at::kDouble);
  return (ad - bd).abs().max().item<double>() / std::max(bd.abs().max().item<double>(), 1e-300);
}

struct SsimRun {
  double value = 0;
  at::Tensor grad;
};

// Value and ∂(0.5 · SSIM)/∂rendered; 0.5 checks that the incoming gradient is applied.
SsimRun run_ssim(const at::Tensor& rendered, const at::Tensor& target) {
  const at::Tensor input = rendered.clone().requires_grad_(true);
  const at::Tensor value = fused_ssim(input, target);
  return {value.item<double>(), torch::autograd::grad({0.5 * value}, {input})[0]};
}

class FusedSsimCuda : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  }
};

class FusedSsimCudaParity : public ::testing::TestWithParam<Shape> {
 protected:
  void SetUp() override {
    if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  }
};

INSTANTIATE_TEST_SUITE_P(Shapes, FusedSsimCudaParity,
                         ::testing::Values(Shape{1, 3, 7, 5}, Shape{2, 3, 37, 29}, Shape{3, 64, 48},
                                           Shape{1, 2, 1, 13}, Shape{3, 768, 1024}));

TEST_P(FusedSsimCudaParity, MatchesCpuInDouble) {
  const at::Tensor a = at::rand(GetParam());
  for (const at::Tensor& b : {(a + 0.1 * at::randn_like(a)).clamp(0, 1), at::rand_like(a)}) {
    const SsimRun cpu = run_ssim(a.to(at::kDouble), b.to(at::kDouble));
    const SsimRun gpu = run_ssim(a.to(at::kCUDA), b.to(at::kCUDA));
    EXPECT_EQ(gpu.grad.device().type(), at::kCUDA);
    EXPECT_EQ(gpu.grad.scalar_type(), at::kFloat);
    // Unrelated images have SSIM near 0: compare against the scale of SSIM.
    EXPECT_LT(std::abs(gpu.value - cpu.value), 1e-5 * std::max(std::abs(cpu.value), 0.1));
    EXPECT_LT(relative_error(gpu.grad, cpu.grad), 1e-4);
    EXPECT_LT(max_error(gpu.grad, cpu.grad), 1e-4);
  }
}

TEST_F(FusedSsimCuda, IsOneForIdenticalImages) {
  const at::Tensor image = at::rand({2, 3, 45, 70}, at::TensorOptions().device(at::kCUDA));
  EXPECT_NEAR(fused_ssim(image, image).item<double>(), 1.0, 1e-6);
}

TEST_F(FusedSsimCuda, SameValueWithoutGradient) {
  const at::Tensor a = at::rand({3, 100, 70}, at::TensorOptions().device(at::kCUDA));
  const at::Tensor b = (a + 0.1 * at::randn_like(a)).clamp(0, 1);
  const double with_gradient = fused_ssim(a.clone().requires_grad_(true), b).item<double>();
  const at::NoGradGuard no_grad;
  EXPECT_EQ(fused_ssim(a, b).item<double>(), with_gradient);
}

TEST_F(FusedSsimCuda, RejectsDouble) {
  const at::Tensor a = at::rand({3, 8, 8}, at::TensorOptions().dtype(at::kDouble).device(at::kCUDA));
  EXPECT_THROW(fused_ssim(a, a), c10::Error);
}

}  // namespace
}  // namespace tega::nn
