// encode_positions (the fused op) against the tensor-op definition
// PositionalEncoding::encode / axis_derivatives: values, zero padding and
// the gradients autograd takes through both outputs, on the CPU in double.
#include "tega/nn/positional_encoding.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

namespace tega::nn {
namespace {

PositionalEncoding test_encoding() {
  PositionalEncoding pe;
  pe.frequencies = 5;
  pe.depth_scale = 3.0;
  return pe;
}

// uvd over the range training meets: u, v in [0,1], d in [-0.05, 0.2] m.
at::Tensor uvd_in_training_range(int64_t n) {
  const at::Tensor uv = at::rand({n, 2}, at::kDouble);
  const at::Tensor d = at::rand({n, 1}, at::kDouble) * 0.25 - 0.05;
  return at::cat({uv, d}, 1);
}

TEST(EncodePositions, MatchesTheDefinitionWithZeroPadding) {
  const PositionalEncoding pe = test_encoding();
  const at::Tensor uvd = uvd_in_training_range(37);
  const EncodedPositions fused = encode_positions(pe, uvd, at::kDouble, /*with_derivatives=*/true);
  ASSERT_EQ(fused.encoding.sizes(), (std::vector<int64_t>{37, aligned_width(pe.channels())}));
  ASSERT_EQ(fused.derivatives.sizes(), (std::vector<int64_t>{3, 37, aligned_width(pe.features())}));
  ASSERT_GT(aligned_width(pe.channels()), pe.channels()) << "the test must cover padding";
  EXPECT_TRUE(at::allclose(fused.encoding.narrow(1, 0, pe.channels()), pe.encode(uvd), 1e-12, 1e-12));
  EXPECT_TRUE(at::allclose(fused.derivatives.narrow(2, 0, pe.features()), pe.axis_derivatives(uvd), 1e-12, 1e-12));
  EXPECT_EQ(
      fused.encoding.narrow(1, pe.channels(), aligned_width(pe.channels()) - pe.channels()).abs().max().item<double>(),
      0.0);
  EXPECT_EQ(fused.derivatives.narrow(2, pe.features(), aligned_width(pe.features()) - pe.features())
                .abs()
                .max()
                .item<double>(),
            0.0);

  const EncodedPositions encoding_only = encode_positions(pe, uvd, at::kDouble, /*with_derivatives=*/false);
  EXPECT_FALSE(encoding_only.derivatives.defined());
  EXPECT_TRUE(at::equal(encoding_only.encoding, fused.encoding));
}

// A random linear functional of both outputs, differentiated w.r.t. uvd
// through the fused op and through the tensor-op definition (whose
// derivative output autograd differentiates a second time).
TEST(EncodePositions, GradientsMatchTheDefinition) {
  const PositionalEncoding pe = test_encoding();
  const at::Tensor uvd = uvd_in_training_range(29);
  const at::Tensor weight_encoding = at::randn({29, pe.channels()}, at::kDouble);
  const at::Tensor weight_derivatives = at::randn({3, 29, pe.features()}, at::kDouble);
  for (const bool with_derivatives : {true, false}) {
    const at::Tensor fused_uvd = uvd.clone().requires_grad_(true);
    const EncodedPositions fused = encode_positions(pe, fused_uvd, at::kDouble, with_derivatives);
    at::Tensor fused_loss = (fused.encoding.narrow(1, 0, pe.channels()) * weight_encoding).sum();
    if (with_derivatives)
      fused_loss = fused_loss + (fused.derivatives.narrow(2, 0, pe.features()) * weight_derivatives).sum();

    const at::Tensor reference_uvd = uvd.clone().requires_grad_(true);
    at::Tensor reference_loss = (pe.encode(reference_uvd) * weight_encoding).sum();
    if (with_derivatives)
      reference_loss = reference_loss + (pe.axis_derivatives(reference_uvd) * weight_derivatives).sum();

    const at::Tensor fused_grad = torch::autograd::grad({fused_loss}, {fused_uvd})[0];
    const at::Tensor reference_grad = torch::autograd::grad({reference_loss}, {reference_uvd})[0];
    EXPECT_GT(reference_grad.abs().max().item<double>(), 1e-3);
    EXPECT_TRUE(at::allclose(fused_grad, reference_grad, 1e-10, 1e-10)) << "with_derivatives " << with_derivatives;
  }
}

TEST(EncodePositions, RejectsAnOutputTypeOtherThanUvdsOnTheCpu) {
  EXPECT_THROW(encode_positions(test_encoding(), uvd_in_training_range(3), at::kFloat, false), c10::Error);
  EXPECT_THROW(encode_positions(test_encoding(), at::zeros({3, 2}, at::kDouble), at::kDouble, false), c10::Error);
}

}  // namespace
}  // namespace tega::nn
