#pragma once
// TeGA's training losses (§3.6, Eq. 6), except the VGG term (vgg_loss.h):
//
//   L = 0.8 L1 + 0.2 L_D-SSIM + λ_VGG L_VGG + λ_JD L_JD
//
// Images are [C,H,W] or [B,C,H,W] floats in [0,1].

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>


namespace tega::nn {

// Mean absolute difference.
at::Tensor l1_image_loss(const at::Tensor& rendered, const at::Tensor& target);

// Mean over `levels` coarser scales (2x, 4x, ... box averages) of the mean
// absolute difference: L1 on an image pyramid without its finest level. A
// misalignment wider than the skin's texture gives L1 and D-SSIM at full
// resolution no direction to move in; on the coarse levels it does. It stands
// in for the coarse gradients of the paper's VGG term when no weights exist.
// An image side that a level cannot halve drops its last pixel (average pooling).
at::Tensor pyramid_l1_loss(const at::Tensor& rendered, const at::Tensor& target, int levels);

// Mean SSIM as in 3DGS: 11x11 Gaussian window (σ = 1.5) applied per channel
// by conv2d with zero padding (so the output keeps the image size),
// C1 = 0.01², C2 = 0.03² for a data range of 1. Plain torch ops: the
// reference that fused_ssim (fused_ssim.h) is tested against.
at::Tensor ssim(const at::Tensor& a, const at::Tensor& b);
// 1 - SSIM, the form 3DGS weighs by 0.2 (not (1 - SSIM)/2), through
// fused_ssim: differentiable in `rendered` only, the target must not require grad.
at::Tensor dssim_loss(const at::Tensor& rendered, const at::Tensor& target);

// The deformation smoothness term, Eq. 8: ‖J_D‖_F² over random uvd samples.
// The paper writes a sum over its 100K samples; with λ_JD starting at 1 that
// would outweigh the photometric terms (≈ 0.05) by orders of magnitude, so the
// caller chooses the normalisation explicitly and the trainer uses the mean
// (a sum is the mean times the sample count, i.e. only a rescaled λ).
enum class Reduction { mean, sum };
at::Tensor jacobian_smoothness_loss(const at::Tensor& jacobians /* [N,3,3] */, Reduction reduction);

// Uniform uvd samples [count,3] for the smoothness loss: u, v in [0,1],
// d in [-0.05, 0.2] m (the paper's [-50, 200] mm).
constexpr double kSmoothnessDepthMin = -0.05;
constexpr double kSmoothnessDepthMax = 0.2;
at::Tensor sample_smoothness_uvd(int64_t count, const at::TensorOptions& options,
                                 c10::optional<at::Generator> generator = c10::nullopt);

}  // namespace tega::nn
