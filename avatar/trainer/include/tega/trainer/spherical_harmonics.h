#pragma once
// View-dependent colour from real spherical harmonics (degree 0-3), in the
// convention of 3D Gaussian Splatting: rgb = max(Σ_k Y_k(dir) h_k + 0.5, 0).
// Training lets the rasterizer evaluate the SH (the shading multiplier is
// folded into the coefficients, AvatarModel::pose); these tensor-op versions
// are the reference that tests hold that against.

#include <ATen/ATen.h>

namespace tega::trainer {

constexpr int sh_coefficients(int degree) { return (degree + 1) * (degree + 1); }
constexpr double kShConstant = 0.28209479177387814;  // Y_0^0 = C0

// sh [N, K, 3] with K >= (degree+1)²; directions [N, 3] (any length, from the
// camera centre to the Gaussian) -> rgb [N, 3]. Differentiable in sh and
// directions.
at::Tensor sh_to_rgb(const at::Tensor& sh, const at::Tensor& directions, int degree);
// The same with the coefficients split as the Gaussians store them: sh_dc
// [N,1,3] and sh_rest [N,K-1,3] (no [N,K,3] copy is made).
at::Tensor sh_to_rgb(const at::Tensor& sh_dc, const at::Tensor& sh_rest, const at::Tensor& directions, int degree);

// The first `used` SH coefficients [N,used,3] of Gaussians whose colour is
// multiplied by shading [N] (> 0), for the rasterizer to evaluate:
// S·max(c, 0) = max(S·c, 0) with dc' = S·dc + ½(S − 1)/C0 and rest' = S·rest.
// sh_dc [N,1,3], sh_rest [N,K−1,3] with K ≥ used. One pass forward and one
// back (a CUDA kernel on a GPU); differentiable in all three.
at::Tensor shaded_sh(const at::Tensor& sh_dc, const at::Tensor& sh_rest, const at::Tensor& shading, int used);

}  // namespace tega::trainer
