#pragma once
// Differentiable tile rasterizer for 3D Gaussians (docs/rasterizer.md).
//
// rasterize() runs the CUDA pipeline when the tensors live on a GPU and the
// multi-threaded CPU pipeline otherwise (float or double). Gradients flow to
// means, covariances, colours, opacities and background through autograd.

#include <ATen/core/Tensor.h>

#include <array>
#include <vector>

namespace tega::splat {

// A pinhole camera: x_cam = R x_world + t, OpenCV axes, pixel (0,0) is the
// centre of the top-left pixel.
struct RasterCamera {
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major
  std::array<double, 3> translation{0, 0, 0};
  double fx = 1, fy = 1, cx = 0, cy = 0;
};

struct RasterSettings {
  int width = 0, height = 0;   // every camera renders this size
  double near_plane = 0.01;    // metres; Gaussians whose mean lies outside are culled
  double far_plane = 100.0;
  bool antialiased = false;    // Mip-Splatting's 2D filter with opacity compensation
  int sh_degree = 3;           // degree evaluated when colours are SH coefficients
  bool per_camera_rgb = false; // colours [C, N, 3] are RGB per camera, not SH [N, K, 3]
};

// Densification statistics, accumulated over backward passes: for every
// camera that sees Gaussian g, |d loss / d mean2D| (pixels) is added to
// grad_norm_sum[g] and 1 to visible_count[g].
struct MeanGradientStats {
  at::Tensor grad_norm_sum;  // [N], the means' dtype and device
  at::Tensor visible_count;  // [N] int32

  static MeanGradientStats zeros(const at::Tensor& means);
};

struct RasterOutput {
  at::Tensor rgb;      // [C, H, W, 3], background blended in
  at::Tensor alpha;    // [C, H, W], accumulated opacity
  at::Tensor depth;    // [C, H, W], expected camera z: Σ wᵢ zᵢ / alpha (0 where alpha ≤ 1e-10)
  at::Tensor radii;    // [C, N] int32, screen-space radius in pixels, 0 when culled
  at::Tensor visible;  // [C, N] bool, radii > 0
};

// means [N, 3]; covariances [N, 6] (xx, xy, xz, yy, yz, zz, world frame);
// colors: SH coefficients [N, K, 3] (K ≥ (sh_degree+1)², colour =
// max(SH + 0.5, 0), view direction from the camera centre to the mean), or
// RGB [N, 3], or RGB per camera [C, N, 3] with settings.per_camera_rgb; opacities [N] in [0, 1]; background [3].
// All floating tensors share one dtype and device. stats, when given, is
// updated during the backward pass.
RasterOutput rasterize(const at::Tensor& means, const at::Tensor& covariances, const at::Tensor& colors,
                       const at::Tensor& opacities, const at::Tensor& background,
                       const std::vector<RasterCamera>& cameras, const RasterSettings& settings,
                       const MeanGradientStats* stats = nullptr);

// Σ = R diag(scales²) Rᵀ as [N, 6], from scales [N, 3] and quaternions
// [N, 4] (w, x, y, z; normalised here). Differentiable through autograd.
at::Tensor covariance_from_scale_rotation(const at::Tensor& scales, const at::Tensor& quaternions);

}  // namespace tega::splat
