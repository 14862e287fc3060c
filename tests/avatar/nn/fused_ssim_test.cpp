// The fused SSIM (CPU path) against the torch-op ssim() it replaces in the
// loss: values, gradients (autograd through ssim(), in double), finite
// differences, and exactly 1 for identical images. The CUDA kernels' parity
// with this path is in fused_ssim_cuda_test.cpp.

#include "tega/nn/fused_ssim.h"
#include "tega/nn/losses.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <vector>
#include "../tensor_compare.h"

namespace tega::nn {
namespace {

using Shape = std::vector<int64_t>;

using test::relative_error;

// A target resembling the rendering, as in training: SSIM well inside (0, 1).
at::Tensor noisy_copy(const at::Tensor& image) { return (image + 0.1 * at::randn_like(image)).clamp(0, 1); }

at::Tensor gradient(const at::Tensor& value, const at::Tensor& input) {
  return torch::autograd::grad({value}, {input})[0];
}

// Smaller than a tile, not multiples of it, batched and not, a single row.
class FusedSsimShapes : public ::testing::TestWithParam<Shape> {};

INSTANTIATE_TEST_SUITE_P(Shapes, FusedSsimShapes,
                         ::testing::Values(Shape{1, 3, 7, 5}, Shape{2, 3, 37, 29}, Shape{3, 64, 48},
                                           Shape{1, 2, 1, 13}));

TEST_P(FusedSsimShapes, ForwardMatchesTorchOpSsim) {
  const at::Tensor a = at::rand(GetParam(), at::kDouble);
  for (const at::Tensor& b : {noisy_copy(a), at::rand_like(a)}) {
    EXPECT_NEAR(fused_ssim(a, b).item<double>(), ssim(a, b).item<double>(), 1e-12);
    const at::Tensor af = a.to(at::kFloat), bf = b.to(at::kFloat);
    const at::Tensor value = fused_ssim(af, bf);
    EXPECT_EQ(value.scalar_type(), at::kFloat);
    EXPECT_EQ(value.dim(), 0);
    EXPECT_NEAR(value.item<double>(), ssim(af, bf).item<double>(), 1e-5);
  }
}

TEST_P(FusedSsimShapes, GradientMatchesAutogradThroughTorchOpSsim) {
  const at::Tensor a = at::rand(GetParam(), at::kDouble).requires_grad_(true);
  for (const at::Tensor& b : {noisy_copy(a.detach()), at::rand_like(a)}) {
    // A factor other than 1 checks that the incoming gradient is applied.
    const at::Tensor fused = gradient(-0.7 * fused_ssim(a, b), a);
    const at::Tensor reference = gradient(-0.7 * ssim(a, b), a);
    EXPECT_LT(relative_error(fused, reference), 1e-10);
    EXPECT_LT((fused - reference).abs().max().item<double>(), 1e-12);
  }
}

TEST_P(FusedSsimShapes, FloatGradientIsCloseToDouble) {
  const at::Tensor a = at::rand(GetParam(), at::kDouble);
  const at::Tensor b = noisy_copy(a);
  const at::Tensor ad = a.clone().requires_grad_(true);
  const at::Tensor af = a.to(at::kFloat).requires_grad_(true);
  const at::Tensor reference = gradient(fused_ssim(ad, b), ad);
  const at::Tensor single = gradient(fused_ssim(af, b.to(at::kFloat)), af);
  EXPECT_EQ(single.scalar_type(), at::kFloat);
  EXPECT_LT(relative_error(single, reference), 1e-4);
}

TEST(FusedSsim, GradientMatchesFiniteDifferences) {
  const at::Tensor a = at::rand({2, 3, 13, 11}, at::kDouble);
  const at::Tensor b = noisy_copy(a);
  const at::Tensor input = a.clone().requires_grad_(true);
  const at::Tensor grad = gradient(fused_ssim(input, b), input).view(-1);
  at::Tensor x = a.clone();
  const at::Tensor flat = x.view(-1);
  const double h = 1e-6;
  // Corners, edges and interior pixels of different planes.
  for (int64_t i : {int64_t(0), int64_t(10), int64_t(60), int64_t(142), int64_t(300), int64_t(571), flat.numel() - 1}) {
    const double original = flat[i].item<double>();
    flat[i] = original + h;
    const double plus = fused_ssim(x, b).item<double>();
    flat[i] = original - h;
    const double minus = fused_ssim(x, b).item<double>();
    flat[i] = original;
    EXPECT_NEAR(grad[i].item<double>(), (plus - minus) / (2 * h), 1e-9) << "element " << i;
  }
}

TEST(FusedSsim, IsExactlyOneWithZeroGradientForIdenticalImages) {
  for (const auto dtype : {at::kFloat, at::kDouble}) {
    const at::Tensor image = at::rand({2, 3, 19, 23}, dtype);
    EXPECT_EQ(fused_ssim(image, image).item<double>(), 1.0) << dtype;
  }
  // SSIM is at its maximum there.
  const at::Tensor image = at::rand({3, 19, 23}, at::kDouble);
  const at::Tensor input = image.clone().requires_grad_(true);
  EXPECT_LT(gradient(fused_ssim(input, image), input).abs().max().item<double>(), 1e-14);
}

// The trainer passes a permuted [H,W,3] rendering.
TEST(FusedSsim, AcceptsANonContiguousRendering) {
  const at::Tensor hwc = at::rand({17, 21, 3}, at::kDouble).requires_grad_(true);
  const at::Tensor rendered = hwc.permute({2, 0, 1});
  const at::Tensor target = noisy_copy(rendered.detach()).contiguous();
  const at::Tensor value = fused_ssim(rendered, target);
  EXPECT_NEAR(value.item<double>(), ssim(rendered, target).item<double>(), 1e-12);
  EXPECT_LT(relative_error(gradient(value, hwc), gradient(ssim(rendered, target), hwc)), 1e-10);
}

TEST(FusedSsim, SameValueWithoutGradient) {
  const at::Tensor a = at::rand({2, 3, 20, 30}, at::kDouble);
  const at::Tensor b = noisy_copy(a);
  const double with_gradient = fused_ssim(a.clone().requires_grad_(true), b).item<double>();
  EXPECT_EQ(fused_ssim(a, b).item<double>(), with_gradient);
  const at::NoGradGuard no_grad;
  // Outside grad mode a target that requires grad is harmless.
  EXPECT_EQ(fused_ssim(a.clone().requires_grad_(true), b.clone().requires_grad_(true)).item<double>(), with_gradient);
}

TEST(FusedSsim, RejectsBadInputs) {
  const at::Tensor a = at::rand({3, 8, 8});
  EXPECT_THROW(fused_ssim(a, a.clone().requires_grad_(true)), c10::Error);
  EXPECT_THROW(fused_ssim(a, at::rand({3, 8, 9})), c10::Error);
  EXPECT_THROW(fused_ssim(a[0], a[0]), c10::Error);
  EXPECT_THROW(fused_ssim(a, a.to(at::kDouble)), c10::Error);
  EXPECT_THROW(fused_ssim(a.to(at::kHalf), a.to(at::kHalf)), c10::Error);
  EXPECT_THROW(fused_ssim(at::rand({3, 0, 8}), at::rand({3, 0, 8})), c10::Error);
}

TEST(DssimLoss, IsOneMinusTheTorchOpSsim) {
  const at::Tensor a = at::rand({1, 3, 33, 40}, at::kDouble);
  const at::Tensor b = noisy_copy(a);
  EXPECT_NEAR(dssim_loss(a, b).item<double>(), 1 - ssim(a, b).item<double>(), 1e-12);
}

}  // namespace
}  // namespace tega::nn
