#pragma once
// World-space Gaussians in the layout of 3D Gaussian Splatting's PLY files,
// which common splat viewers read (docs/render-eval-export.md):
//
//   binary_little_endian, one "vertex" element, float32 properties
//   x y z  nx ny nz  f_dc_0..2  f_rest_0..(3(K-1)-1)  opacity  scale_0..2  rot_0..3
//
// f_rest is channel-major: the K-1 higher coefficients of red, then green,
// then blue. opacity is a logit, scale a log standard deviation, rot a
// quaternion (w, x, y, z). Normals are written as zeros, as 3DGS does.

#include <ATen/ATen.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/camera.h"

namespace tega::tools {

struct GaussianCloud {
  at::Tensor means;          // [N,3] world, metres
  at::Tensor sh;             // [N,K,3] SH coefficients, K = (degree+1)², colour = max(SH + 0.5, 0)
  at::Tensor opacity_logit;  // [N]
  at::Tensor log_scale;      // [N,3] log standard deviations along the rotated axes
  at::Tensor rotation;       // [N,4] unit quaternion (w, x, y, z)

  int64_t size() const { return means.size(0); }
  int sh_degree() const;
  at::Tensor covariances() const;  // [N,6] packed xx, xy, xz, yy, yz, zz
  at::Tensor opacities() const;    // [N] in (0,1)
  GaussianCloud to(const at::Device& device, at::ScalarType dtype) const;
};

// The property names of a cloud of this SH degree, in file order.
std::vector<std::string> ply_property_names(int sh_degree);

// Atomic. Stores float32 whatever the cloud's dtype.
void write_gaussian_ply(const GaussianCloud& cloud, const std::filesystem::path& file);
// Reads any binary little-endian or ASCII PLY whose vertex element has the
// properties above as float (or double) in any order; other properties (and
// the normals) are ignored. The SH degree follows the f_rest count (0, 9, 24
// or 45). Throws tega::Error naming the file for anything else. float32, CPU.
GaussianCloud read_gaussian_ply(const std::filesystem::path& file);

// The cloud rasterized from `camera` (an undistorted pinhole): float RGB [3,H,W].
at::Tensor render_cloud(const GaussianCloud& cloud, const Camera& camera, const at::Tensor& background,
                        bool antialiased);

}  // namespace tega::tools
