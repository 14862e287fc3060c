#pragma once
// SSIM with a hand-written, fused forward and backward (CPU: float and
// double; CUDA: float). The torch-op ssim() of losses.h runs five full-image
// convolutions and a dozen elementwise ops, all kept for autograd (~17 ms
// forward alone at 3072x2048 on an H100); this computes the five blurred
// moments in one pass and backpropagates with one more. ssim() stays as the
// reference the tests hold this to (docs/networks-and-losses.md).

#include <ATen/core/Tensor.h>

namespace tega::nn {

// Mean SSIM of [C,H,W] or [B,C,H,W] images, defined exactly as ssim(). The
// gradient flows to `rendered` only: a target that requires grad is refused
// (while grad mode is on) rather than silently treated as a constant.
at::Tensor fused_ssim(const at::Tensor& rendered, const at::Tensor& target);

}  // namespace tega::nn
