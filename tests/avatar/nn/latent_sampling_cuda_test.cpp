// sample_latent: the CUDA kernels against the CPU loops (values and
// gradients); skips where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "tega/nn/encoders.h"

namespace {

std::vector<at::Tensor> run(const at::Tensor& latent_in, const at::Tensor& uv_in, const at::Tensor& weights,
                            const at::Device& device) {
  const at::Tensor latent = latent_in.to(device).requires_grad_(true), uv = uv_in.to(device).requires_grad_(true);
  const at::Tensor sampled = tega::nn::sample_latent(latent, uv);
  const auto g = torch::autograd::grad({(sampled * weights.to(device)).sum()}, {latent, uv});
  return {sampled.detach().cpu(), g[0].cpu(), g[1].cpu()};
}

TEST(SampleLatentCuda, MatchesTheCpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  for (const int64_t channels : {64, 8, 5}) {  // warp-sized, 8-lane and single-lane groups
    const at::Tensor latent = at::randn({channels, 64, 48});
    const at::Tensor uv = at::rand({20000, 2}) * 1.2 - 0.1;
    const at::Tensor weights = at::randn({20000, channels});
    const auto cpu = run(latent, uv, weights, at::kCPU);
    const auto gpu = run(latent, uv, weights, at::Device(at::kCUDA, 0));
    EXPECT_TRUE(at::allclose(gpu[0], cpu[0], 1e-5, 1e-5)) << channels;
    EXPECT_TRUE(at::allclose(gpu[1], cpu[1], 1e-4, 1e-4)) << channels;
    EXPECT_TRUE(at::allclose(gpu[2], cpu[2], 1e-3, 1e-3)) << channels;
  }
}

}  // namespace
