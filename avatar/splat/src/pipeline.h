#pragma once
// Raw-pointer description of one rasterizer call, shared by the CPU pipeline
// and the CUDA kernels (no torch types: nvcc compiles this in C++17).
//
// Index conventions: a projected Gaussian is addressed as c * N + g (camera
// major); a tile as c * tiles_x * tiles_y + ty * tiles_x + tx; images are
// [C, H, W] (rgb [C, H, W, 3]).

#include <tega/splat/gaussian_math.h>

#include <cstdint>

namespace tega::splat {

template <typename T>
struct RasterInputs {
  int64_t num_gaussians = 0;
  int32_t num_cameras = 0;
  const T* means = nullptr;        // [N, 3]
  const T* covariances = nullptr;  // [N, 6]: xx, xy, xz, yy, yz, zz
  const T* colors = nullptr;       // SH [N, K, 3], or RGB [N, 3] / [C, N, 3]
  const T* opacities = nullptr;    // [N]
  const T* background = nullptr;   // [3]
  int32_t sh_coefficients = 0;     // K; 0 when colours are RGB
  int32_t sh_degree = 0;           // degree evaluated, (degree+1)² ≤ K
  int64_t color_camera_stride = 0; // RGB colours: N*3 when given per camera, else 0
  const CameraParams<T>* cameras = nullptr;  // [C]
  ImageGeometry geometry{};
  ProjectionSettings projection{};

  TEGA_HD int64_t num_projected() const { return num_gaussians * num_cameras; }
  TEGA_HD int64_t num_tiles() const { return int64_t(geometry.tiles_x) * geometry.tiles_y * num_cameras; }
  TEGA_HD int64_t num_pixels() const { return int64_t(geometry.width) * geometry.height * num_cameras; }
};

// Per projected Gaussian, [C * N] each.
template <typename T>
struct ProjectedBuffers {
  Splat2D<T>* splats = nullptr;
  TileRect* rects = nullptr;
  int32_t* radii = nullptr;
  ColorJacobian<T>* color_jacobians = nullptr;  // SH colours only (else null)
};

// Each tile's run [begin, end) in the list of projected-Gaussian ids, which
// is sorted by tile and, within a tile, front to back.
struct TileBins {
  const int32_t* ranges = nullptr;        // [num_tiles, 2]
  const int32_t* gaussian_ids = nullptr;  // [count], c * N + g
  int64_t count = 0;                      // tile-Gaussian intersections
};

// Per-pixel outputs of the forward pass, and what the backward pass reads.
template <typename T>
struct ImageBuffers {
  T* rgb = nullptr;                  // [C, H, W, 3], background included
  T* alpha = nullptr;                // [C, H, W]
  T* depth = nullptr;                // [C, H, W], expected depth Σ w z / alpha (expected_depth)
  T* final_transmittance = nullptr;  // [C, H, W]
  int32_t* last = nullptr;           // [C, H, W], splats blended: 1 + last index in the tile list
};

template <typename T>
struct ImageGradients {
  const T* rgb = nullptr;    // [C, H, W, 3]
  const T* alpha = nullptr;  // [C, H, W]
  const T* depth = nullptr;  // [C, H, W]; null when the loss does not depend on depth
};

// Outputs of the backward pass. grad_colors has the colours' shape; the
// statistics are optional (null) and accumulate across calls.
template <typename T>
struct InputGradients {
  T* means = nullptr;
  T* covariances = nullptr;
  T* colors = nullptr;
  T* opacities = nullptr;
  T* mean2d_grad_norm_sum = nullptr;  // [N] += |d loss / d mean2D| per camera seeing it
  int32_t* visible_count = nullptr;   // [N] += number of cameras seeing it
};

// ---------------------------------------------------------------------------
// Per-Gaussian steps that both pipelines run once per index.

// Projects Gaussian g into camera c, colour included. With SH colours, g's
// coefficients are read from sh_row (g's row of in.colors, or a copy of it
// that the caller moved) and the colour's Jacobian for the backward pass is
// written to color_jacobian. Returns the radius (0: culled).
template <typename T>
TEGA_HD int32_t project_one(const RasterInputs<T>& in, int32_t c, int64_t g, const T* sh_row, Splat2D<T>& sp,
                            TileRect& rect, ColorJacobian<T>* color_jacobian) {
  const CameraParams<T>& cam = in.cameras[c];
  const int32_t radius =
      project_gaussian(cam, in.geometry, in.projection, in.means + 3 * g, in.covariances + 6 * g, in.opacities[g], sp, rect);
  if (radius == 0) return 0;
  T rgb[3];
  if (in.sh_coefficients > 0) {
    const T* mean = in.means + 3 * g;
    const T direction[3] = {mean[0] - cam.centre[0], mean[1] - cam.centre[1], mean[2] - cam.centre[2]};
    sh_to_rgb(in.sh_degree, sh_row, direction, rgb, *color_jacobian);
  } else {
    const T* src = in.colors + in.color_camera_stride * c + 3 * g;
    rgb[0] = src[0];
    rgb[1] = src[1];
    rgb[2] = src[2];
  }
  sp.red = rgb[0];
  sp.green = rgb[1];
  sp.blue = rgb[2];
  return radius;
}

// Backward of project_one for Gaussian g over every camera: reads the splat
// gradients [C * N] and writes (not adds) all of g's input gradients. With
// SH colours, it reads the colour Jacobians [C * N] that the forward pass
// kept and writes the coefficients' gradient to grad_sh_row (g's row of
// out.colors, or a copy of it that the caller moves).
template <typename T>
TEGA_HD void project_backward_one(const RasterInputs<T>& in, const int32_t* radii, const Splat2D<T>* splat_grads,
                                  const ColorJacobian<T>* color_jacobians, int64_t g, T* grad_sh_row,
                                  const InputGradients<T>& out) {
  T grad_mean[3] = {T(0), T(0), T(0)};
  T grad_cov[6] = {T(0), T(0), T(0), T(0), T(0), T(0)};
  T grad_opacity = T(0);
  const int64_t n = in.num_gaussians;
  const bool sh = in.sh_coefficients > 0;
  T* grad_sh = sh ? grad_sh_row : nullptr;
  bool sh_written = false;  // the first camera writes grad_sh, later ones add
  T grad_rgb_shared[3] = {T(0), T(0), T(0)};
  T stat_norm = T(0);
  int32_t stat_visible = 0;
  for (int32_t c = 0; c < in.num_cameras; ++c) {
    const int64_t index = c * n + g;
    const bool visible = radii[index] > 0;
    const Splat2D<T> grad = splat_grads[index];
    const T grad_rgb[3] = {grad.red, grad.green, grad.blue};
    if (!sh && in.color_camera_stride != 0) {
      T* dst = out.colors + in.color_camera_stride * c + 3 * g;
      for (int ch = 0; ch < 3; ++ch) dst[ch] = visible ? grad_rgb[ch] : T(0);
    }
    if (!visible) continue;
    ++stat_visible;
    stat_norm += math_sqrt(grad.u * grad.u + grad.v * grad.v);
    const CameraParams<T>& cam = in.cameras[c];
    const T* mean = in.means + 3 * g;
    if (sh) {
      const T direction[3] = {mean[0] - cam.centre[0], mean[1] - cam.centre[1], mean[2] - cam.centre[2]};
      sh_to_rgb_backward(in.sh_degree, in.sh_coefficients, color_jacobians[index], direction, grad_rgb, sh_written,
                         grad_sh, grad_mean);  // d direction / d mean = I
      sh_written = true;
    } else if (in.color_camera_stride == 0) {
      for (int ch = 0; ch < 3; ++ch) grad_rgb_shared[ch] += grad_rgb[ch];
    }
    project_gaussian_backward(cam, in.geometry, in.projection, mean, in.covariances + 6 * g, in.opacities[g], grad,
                              grad_mean, grad_cov, &grad_opacity);
  }
  for (int k = 0; k < 3; ++k) out.means[3 * g + k] = grad_mean[k];
  for (int k = 0; k < 6; ++k) out.covariances[6 * g + k] = grad_cov[k];
  out.opacities[g] = grad_opacity;
  if (sh && !sh_written)
    for (int k = 0; k < 3 * in.sh_coefficients; ++k) grad_sh[k] = T(0);
  if (!sh && in.color_camera_stride == 0)
    for (int ch = 0; ch < 3; ++ch) out.colors[3 * g + ch] = grad_rgb_shared[ch];
  if (out.mean2d_grad_norm_sum) {
    out.mean2d_grad_norm_sum[g] += stat_norm;
    out.visible_count[g] += stat_visible;
  }
}

}  // namespace tega::splat
