// encode_positions's CUDA kernels (float32 and bfloat16 storage) against the
// CPU loops in double: both outputs and the uvd gradient through each; skips
// where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/cuda.h>

#include <vector>

#include "tega/nn/positional_encoding.h"
#include "../tensor_compare.h"

namespace tega::nn {
namespace {

using test::relative_error;

struct Encoded {
  EncodedPositions out;
  at::Tensor grad_uvd;
};

Encoded encode_with_grad(const PositionalEncoding& pe, const at::Tensor& uvd_in, const at::Tensor& weight_encoding,
                         const at::Tensor& weight_derivatives, const at::Device& device, at::ScalarType input,
                         at::ScalarType stored) {
  const at::Tensor uvd = uvd_in.to(device, input).requires_grad_(true);
  Encoded r;
  r.out = encode_positions(pe, uvd, stored, /*with_derivatives=*/true);
  const at::Tensor loss = (r.out.encoding.to(input) * weight_encoding.to(device, input)).sum() +
                          (r.out.derivatives.to(input) * weight_derivatives.to(device, input)).sum();
  r.grad_uvd = torch::autograd::grad({loss}, {uvd})[0];
  return r;
}

TEST(EncodePositionsCuda, MatchesTheCpuInDouble) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  PositionalEncoding pe;  // the defaults training uses
  const int64_t n = 100003;
  const at::Tensor uvd = at::cat({at::rand({n, 2}, at::kDouble), at::rand({n, 1}, at::kDouble) * 0.25 - 0.05}, 1)
                             .to(at::kFloat)
                             .to(at::kDouble);  // values exact in float
  const at::Tensor weight_encoding = at::randn({n, aligned_width(pe.channels())}, at::kDouble);
  const at::Tensor weight_derivatives = at::randn({3, n, aligned_width(pe.features())}, at::kDouble) * 0.01;
  const Encoded cpu =
      encode_with_grad(pe, uvd, weight_encoding, weight_derivatives, at::kCPU, at::kDouble, at::kDouble);
  // bfloat16 keeps 8 bits of mantissa: 2^-9 relative rounding per entry of
  // the outputs, and of the gradients that reach the kernel.
  struct Case {
    at::ScalarType stored;
    double output_tolerance, gradient_tolerance;
  };
  for (const Case& c : {Case{at::kFloat, 1e-5, 1e-4}, Case{at::kBFloat16, 5e-3, 1e-2}}) {
    const Encoded gpu = encode_with_grad(pe, uvd, weight_encoding, weight_derivatives, at::kCUDA, at::kFloat, c.stored);
    EXPECT_EQ(gpu.out.encoding.scalar_type(), c.stored);
    EXPECT_LT(relative_error(gpu.out.encoding, cpu.out.encoding), c.output_tolerance) << c.stored;
    EXPECT_LT(relative_error(gpu.out.derivatives, cpu.out.derivatives), c.output_tolerance) << c.stored;
    EXPECT_LT(relative_error(gpu.grad_uvd, cpu.grad_uvd), c.gradient_tolerance) << c.stored;
  }
}

}  // namespace
}  // namespace tega::nn
