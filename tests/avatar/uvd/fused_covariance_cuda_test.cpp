// world_covariance_packed: the CUDA kernels against the CPU loops (values and
// gradients); skips where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/cuda.h>

#include "fused_test_support.h"
#include "tega/uvd/fused_covariance.h"

namespace tega::uvd {
namespace {

using test::row_relative_error;

// covariance, std_per_scale and the gradients of Σ weight·covariance, on the CPU.
std::vector<at::Tensor> run(const test::CovarianceInputs& in, const at::Tensor& weight, at::ScalarType dtype,
                            const at::Device& device) {
  const at::Tensor j = in.jacobian.to(device, dtype).requires_grad_(true);
  const at::Tensor q = in.quaternion.to(device, dtype).requires_grad_(true);
  const at::Tensor s = in.log_scale.to(device, dtype).requires_grad_(true);
  const PackedCovariance out = world_covariance_packed(j, q, s);
  const auto g = torch::autograd::grad({(out.covariance * weight.to(device, dtype)).sum()}, {j, q, s});
  return {out.covariance.cpu(), out.std_per_scale.cpu(), g[0].cpu(), g[1].cpu(), g[2].cpu()};
}

TEST(FusedCovarianceCuda, MatchesCpu) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const at::Device gpu(at::kCUDA, 0);
  const auto inputs = test::random_covariance_inputs(100000, 4);
  const at::Tensor weight = at::randn({100000, 6}, at::kDouble);
  const auto cpu = run(inputs, weight, at::kDouble, at::kCPU);
  const auto single = run(inputs, weight, at::kFloat, gpu);
  const auto exact = run(inputs, weight, at::kDouble, gpu);
  const char* names[] = {"covariance", "std_per_scale", "grad jacobian", "grad quaternion", "grad log_scale"};
  for (int k = 0; k < 5; ++k) {
    EXPECT_LT(row_relative_error(single[k], cpu[k]), k < 2 ? 1e-4 : 1e-3) << "float " << names[k];
    EXPECT_LT(row_relative_error(exact[k], cpu[k]), 1e-10) << "double " << names[k];
  }
}

}  // namespace
}  // namespace tega::uvd
