#include "tega/nn/losses.h"

#include "tega/nn/fused_ssim.h"

#include <ATen/ATen.h>

#include <cmath>

namespace tega::nn {
namespace {

constexpr int64_t kWindow = 11;
constexpr double kSigma = 1.5;
constexpr double kC1 = 0.01 * 0.01;
constexpr double kC2 = 0.03 * 0.03;

at::Tensor as_batch(const at::Tensor& image) {
  TORCH_CHECK(image.dim() == 3 || image.dim() == 4, "images must be [C,H,W] or [B,C,H,W], got ", image.sizes());
  return image.dim() == 3 ? image.unsqueeze(0) : image;
}

// Normalised 1D Gaussian, outer product → [C,1,11,11] depthwise kernel.
at::Tensor gaussian_window(int64_t channels, const at::TensorOptions& options) {
  const at::Tensor x = at::arange(kWindow, options) - (kWindow / 2);
  at::Tensor g = at::exp(-(x * x) / (2 * kSigma * kSigma));
  g = g / g.sum();
  return at::outer(g, g).expand({channels, 1, kWindow, kWindow}).contiguous();
}

}  // namespace

at::Tensor l1_image_loss(const at::Tensor& rendered, const at::Tensor& target) {
  TORCH_CHECK(rendered.sizes() == target.sizes(), "L1: sizes differ, ", rendered.sizes(), " vs ", target.sizes());
  return (rendered - target).abs().mean();
}

at::Tensor pyramid_l1_loss(const at::Tensor& rendered, const at::Tensor& target, int levels) {
  TORCH_CHECK(rendered.sizes() == target.sizes(), "pyramid L1: sizes differ, ", rendered.sizes(), " vs ", target.sizes());
  TORCH_CHECK(levels >= 1, "pyramid L1: levels must be at least 1, got ", levels);
  at::Tensor a = as_batch(rendered), b = as_batch(target);
  at::Tensor sum = at::zeros({}, a.options());
  for (int level = 1; level <= levels; ++level) {
    TORCH_CHECK(a.size(2) >= 2 && a.size(3) >= 2, "pyramid L1: a ", rendered.sizes(), " image has no level ", level);
    a = at::avg_pool2d(a, {2, 2});
    b = at::avg_pool2d(b, {2, 2});
    sum = sum + (a - b).abs().mean();
  }
  return sum / levels;
}

at::Tensor ssim(const at::Tensor& a_in, const at::Tensor& b_in) {
  TORCH_CHECK(a_in.sizes() == b_in.sizes(), "SSIM: sizes differ, ", a_in.sizes(), " vs ", b_in.sizes());
  const at::Tensor a = as_batch(a_in), b = as_batch(b_in);
  const int64_t channels = a.size(1);
  const at::Tensor window = gaussian_window(channels, a.options().requires_grad(false));
  const auto blur = [&](const at::Tensor& x) {
    return at::conv2d(x, window, {}, /*stride=*/1, /*padding=*/kWindow / 2, /*dilation=*/1, /*groups=*/channels);
  };
  const at::Tensor mu_a = blur(a), mu_b = blur(b);
  const at::Tensor var_a = blur(a * a) - mu_a * mu_a;
  const at::Tensor var_b = blur(b * b) - mu_b * mu_b;
  const at::Tensor cov = blur(a * b) - mu_a * mu_b;
  const at::Tensor map = ((2 * mu_a * mu_b + kC1) * (2 * cov + kC2)) /
                         ((mu_a * mu_a + mu_b * mu_b + kC1) * (var_a + var_b + kC2));
  return map.mean();
}

at::Tensor dssim_loss(const at::Tensor& rendered, const at::Tensor& target) {
  return 1 - fused_ssim(rendered, target);
}

at::Tensor jacobian_smoothness_loss(const at::Tensor& jacobians, Reduction reduction) {
  TORCH_CHECK(jacobians.dim() == 3 && jacobians.size(1) == 3 && jacobians.size(2) == 3,
              "Jacobians must be [N,3,3], got ", jacobians.sizes());
  const at::Tensor squared_norms = jacobians.square().sum({1, 2});
  return reduction == Reduction::mean ? squared_norms.mean() : squared_norms.sum();
}

at::Tensor sample_smoothness_uvd(int64_t count, const at::TensorOptions& options,
                                 c10::optional<at::Generator> generator) {
  at::Tensor uvd = at::rand({count, 3}, generator, options);
  const at::Tensor scale = at::tensor({1.0, 1.0, kSmoothnessDepthMax - kSmoothnessDepthMin}, options);
  const at::Tensor offset = at::tensor({0.0, 0.0, kSmoothnessDepthMin}, options);
  return uvd * scale + offset;
}

}  // namespace tega::nn
