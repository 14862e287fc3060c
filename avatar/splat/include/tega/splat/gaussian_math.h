#pragma once
// Per-Gaussian and per-pixel math of the rasterizer, shared by the CPU path
// (float and double) and the CUDA kernels. Plain C++17 with no torch types:
// nvcc compiles it with __host__ __device__ qualifiers, g++ without them.
//
// Conventions (docs/rasterizer.md): x_cam = R x_world + t, OpenCV axes,
// pixel (0,0) is the centre of the top-left pixel, 3DGS's SH basis and
// colour = max(SH + 0.5, 0), opacity in [0,1].

#include <cmath>
#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::splat {

// Rendering constants shared by every path (and by the tests' reference).
inline constexpr int kTileSize = 16;
inline constexpr double kLowPassVariance = 0.3;        // px², added to the 2D covariance
inline constexpr double kMinAlpha = 1.0 / 255.0;       // smaller alphas are skipped
inline constexpr double kMaxAlpha = 0.99;              // alpha is clamped here
inline constexpr double kMinTransmittance = 1e-4;      // blending stops below this
inline constexpr double kMinDepthAlpha = 1e-10;        // the expected depth is 0 at smaller alphas
inline constexpr double kFrustumMargin = 0.15;         // J clamp: fraction of the image size
inline constexpr int kMaxShCoefficients = 16;          // degree 3

TEGA_HD float math_sqrt(float x) { return sqrtf(x); }
TEGA_HD double math_sqrt(double x) { return sqrt(x); }
TEGA_HD float math_exp(float x) { return expf(x); }
TEGA_HD double math_exp(double x) { return exp(x); }
TEGA_HD float math_floor(float x) { return floorf(x); }
TEGA_HD double math_floor(double x) { return floor(x); }
TEGA_HD float math_ceil(float x) { return ceilf(x); }
TEGA_HD double math_ceil(double x) { return ceil(x); }
// For bounds that carry a margin: the GPU's one-instruction approximations
// (relative error about 1e-7), exact elsewhere.
TEGA_HD float bound_reciprocal(float x) {
#ifdef __CUDA_ARCH__
  return __fdividef(1.0f, x);
#else
  return 1.0f / x;
#endif
}
TEGA_HD double bound_reciprocal(double x) { return 1.0 / x; }
TEGA_HD float bound_log(float x) {
#ifdef __CUDA_ARCH__
  return __logf(x);
#else
  return logf(x);
#endif
}
TEGA_HD double bound_log(double x) { return log(x); }
template <typename T>
TEGA_HD T math_min(T a, T b) { return a < b ? a : b; }
template <typename T>
TEGA_HD T math_max(T a, T b) { return a < b ? b : a; }

// One pinhole camera, with its centre precomputed for the SH view direction.
template <typename T>
struct CameraParams {
  T rotation[9];  // row-major world-to-camera rotation
  T translation[3];
  T centre[3];  // camera centre in world space, -Rᵀ t
  T fx, fy, cx, cy;
};

// A projected Gaussian as the blending stage reads it. The layout packs into
// three 4-wide vectors so the CUDA kernels load it with 16-byte loads; the
// same struct carries the gradients with respect to each field.
template <typename T>
struct alignas(4 * sizeof(T)) Splat2D {
  T u, v, opacity, depth;  // mean in pixels, opacity after AA compensation, camera z
  T conic_a, conic_b, conic_c, unused0;  // inverse 2D covariance [[a, b], [b, c]]
  T red, green, blue, unused1;
};

// Which tiles and pixels a projected Gaussian may touch. Empty when culled.
struct TileRect {
  int32_t x0, y0, x1, y1;  // tiles [x0, x1) × [y0, y1)
  TEGA_HD int32_t count() const { return (x1 - x0) * (y1 - y0); }
};

struct ImageGeometry {
  int32_t width, height, tiles_x, tiles_y;
};

TEGA_HD ImageGeometry make_geometry(int32_t width, int32_t height) {
  return {width, height, (width + kTileSize - 1) / kTileSize, (height + kTileSize - 1) / kTileSize};
}

// ---------------------------------------------------------------------------
// Small dense algebra on row-major arrays.

template <typename T>
TEGA_HD void mat3_vec(const T* m, const T* v, T* out) {
  for (int r = 0; r < 3; ++r) out[r] = m[3 * r] * v[0] + m[3 * r + 1] * v[1] + m[3 * r + 2] * v[2];
}

template <typename T>
TEGA_HD void mat3t_vec(const T* m, const T* v, T* out) {
  for (int c = 0; c < 3; ++c) out[c] = m[c] * v[0] + m[3 + c] * v[1] + m[6 + c] * v[2];
}

// out = A B Aᵀ for 3x3 A and symmetric 3x3 B (both full row-major).
template <typename T>
TEGA_HD void sandwich3(const T* a, const T* b, T* out) {
  T ab[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      ab[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[3 * r + c] = ab[3 * r] * a[3 * c] + ab[3 * r + 1] * a[3 * c + 1] + ab[3 * r + 2] * a[3 * c + 2];
}

// out = Aᵀ B A for 3x3 A and 3x3 B.
template <typename T>
TEGA_HD void sandwich3_transposed(const T* a, const T* b, T* out) {
  T ba[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      ba[3 * r + c] = b[3 * r] * a[c] + b[3 * r + 1] * a[3 + c] + b[3 * r + 2] * a[6 + c];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[3 * r + c] = a[r] * ba[c] + a[3 + r] * ba[3 + c] + a[6 + r] * ba[6 + c];
}

// Covariance stored as its 6 unique entries (xx, xy, xz, yy, yz, zz).
template <typename T>
TEGA_HD void cov6_to_mat3(const T* c, T* m) {
  m[0] = c[0]; m[1] = c[1]; m[2] = c[2];
  m[3] = c[1]; m[4] = c[3]; m[5] = c[4];
  m[6] = c[2]; m[7] = c[4]; m[8] = c[5];
}

// Gradient of a full symmetric 3x3 matrix to the 6 unique entries: each
// off-diagonal entry appears twice in the matrix.
template <typename T>
TEGA_HD void mat3_grad_to_cov6(const T* g, T* c) {
  c[0] = g[0];
  c[1] = g[1] + g[3];
  c[2] = g[2] + g[6];
  c[3] = g[4];
  c[4] = g[5] + g[7];
  c[5] = g[8];
}

// ---------------------------------------------------------------------------
// Spherical harmonics (real basis, 3DGS signs), written once over a scalar
// type so that Dual3 gives the derivative with respect to the direction.

template <typename T>
struct Dual3 {
  T v, d[3];
};
template <typename T>
TEGA_HD Dual3<T> operator+(Dual3<T> a, Dual3<T> b) {
  return {a.v + b.v, {a.d[0] + b.d[0], a.d[1] + b.d[1], a.d[2] + b.d[2]}};
}
template <typename T>
TEGA_HD Dual3<T> operator-(Dual3<T> a, Dual3<T> b) {
  return {a.v - b.v, {a.d[0] - b.d[0], a.d[1] - b.d[1], a.d[2] - b.d[2]}};
}
template <typename T>
TEGA_HD Dual3<T> operator*(Dual3<T> a, Dual3<T> b) {
  return {a.v * b.v,
          {a.d[0] * b.v + a.v * b.d[0], a.d[1] * b.v + a.v * b.d[1], a.d[2] * b.v + a.v * b.d[2]}};
}
template <typename T>
TEGA_HD Dual3<T> operator*(T s, Dual3<T> a) {
  return {s * a.v, {s * a.d[0], s * a.d[1], s * a.d[2]}};
}
template <typename T>
TEGA_HD Dual3<T> operator*(Dual3<T> a, T s) {
  return s * a;
}

template <typename T>
TEGA_HD void set_constant(T& out, T value) {
  out = value;
}
template <typename T>
TEGA_HD void set_constant(Dual3<T>& out, T value) {
  out = {value, {T(0), T(0), T(0)}};
}

// Calls visit(b, Y_b) for the (degree+1)² basis functions Y_b at the unit
// direction (x, y, z), in order. A visitor that consumes each value at once
// keeps few of them alive: with Dual3 values, an array of all sixteen takes
// 64 registers a thread on the GPU.
template <typename T, typename S, typename Visit>
TEGA_HD void visit_sh_basis(int degree, S x, S y, S z, Visit&& visit) {
  S constant;
  set_constant(constant, T(0.28209479177387814));
  visit(0, constant);
  if (degree < 1) return;
  const T c1 = T(0.4886025119029199);
  visit(1, T(-c1) * y);
  visit(2, c1 * z);
  visit(3, T(-c1) * x);
  if (degree < 2) return;
  const S xx = x * x, yy = y * y, zz = z * z, xy = x * y;
  visit(4, T(1.0925484305920792) * xy);
  visit(5, T(-1.0925484305920792) * (y * z));
  visit(6, T(0.31539156525252005) * (T(2) * zz - xx - yy));
  visit(7, T(-1.0925484305920792) * (x * z));
  visit(8, T(0.5462742152960396) * (xx - yy));
  if (degree < 3) return;
  visit(9, T(-0.5900435899266435) * y * (T(3) * xx - yy));
  visit(10, T(2.890611442640554) * xy * z);
  visit(11, T(-0.4570457994644658) * y * (T(4) * zz - xx - yy));
  visit(12, T(0.3731763325901154) * z * (T(2) * zz - T(3) * xx - T(3) * yy));
  visit(13, T(-0.4570457994644658) * x * (T(4) * zz - xx - yy));
  visit(14, T(1.445305721320277) * z * (xx - yy));
  visit(15, T(-0.5900435899266435) * x * (xx - T(3) * yy));
}

// Colour of one Gaussian seen along `direction` (camera centre -> mean, not
// normalised): SH coefficients [K][3], of which the first (degree+1)² are used.
template <typename T>
TEGA_HD void sh_to_rgb(int degree, const T* sh, const T* direction, T* rgb) {
  const T norm = math_sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                           direction[2] * direction[2]);
  const T inv = norm > T(0) ? T(1) / norm : T(0);
  T sum[3] = {T(0.5), T(0.5), T(0.5)};
  visit_sh_basis<T, T>(degree, direction[0] * inv, direction[1] * inv, direction[2] * inv, [&](int b, T value) {
    for (int ch = 0; ch < 3; ++ch) sum[ch] += value * sh[3 * b + ch];
  });
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = math_max(sum[ch], T(0));
}

// What the backward pass of sh_to_rgb needs besides the direction, kept by
// the forward pass so that the backward pass does not read the coefficients
// again (at 4M Gaussians they are 768 MB). Row ch holds d rgb_ch / d
// direction (x, y, z), then 1 when the clamp at 0 passed the channel (rgb_ch
// > 0, as ReLU decides in torch) and 0 otherwise.
template <typename T>
struct alignas(4 * sizeof(T)) ColorJacobian {
  T rows[3][4];
};

// sh_to_rgb, and the Jacobian its backward pass uses. The basis is evaluated
// once, with its derivatives (Dual3).
template <typename T>
TEGA_HD void sh_to_rgb(int degree, const T* sh, const T* direction, T* rgb, ColorJacobian<T>& jacobian) {
  const T norm = math_sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                           direction[2] * direction[2]);
  const T inv = norm > T(0) ? T(1) / norm : T(0);  // the camera on the mean: no direction gradient
  const T unit[3] = {direction[0] * inv, direction[1] * inv, direction[2] * inv};
  T sum[3] = {T(0.5), T(0.5), T(0.5)};
  T grad_unit[3][3] = {};  // [channel][axis]
  const Dual3<T> x{unit[0], {T(1), T(0), T(0)}}, y{unit[1], {T(0), T(1), T(0)}}, z{unit[2], {T(0), T(0), T(1)}};
  visit_sh_basis<T, Dual3<T>>(degree, x, y, z, [&](int b, const Dual3<T>& value) {
    for (int ch = 0; ch < 3; ++ch) {
      const T coefficient = sh[3 * b + ch];
      sum[ch] += value.v * coefficient;
      for (int k = 0; k < 3; ++k) grad_unit[ch][k] += value.d[k] * coefficient;
    }
  });
  // d unit / d direction = (I - unit unitᵀ) / norm
  for (int ch = 0; ch < 3; ++ch) {
    rgb[ch] = math_max(sum[ch], T(0));
    const T* g = grad_unit[ch];
    const T along = g[0] * unit[0] + g[1] * unit[1] + g[2] * unit[2];
    T* row = jacobian.rows[ch];
    for (int k = 0; k < 3; ++k) row[k] = (g[k] - along * unit[k]) * inv;
    row[3] = rgb[ch] > T(0) ? T(1) : T(0);
  }
}

// Backward of sh_to_rgb for `coefficients` stored SH coefficients, from the
// forward pass's Jacobian: writes (or, with accumulate, adds) d loss / d sh
// to grad_sh and adds d loss / d direction to grad_direction. Channels
// clamped at 0 pass nothing.
template <typename T>
TEGA_HD void sh_to_rgb_backward(int degree, int coefficients, const ColorJacobian<T>& jacobian, const T* direction,
                                const T* grad_rgb, bool accumulate, T* grad_sh, T* grad_direction) {
  T grad_pass[3];
  for (int ch = 0; ch < 3; ++ch) grad_pass[ch] = grad_rgb[ch] * jacobian.rows[ch][3];
  for (int k = 0; k < 3; ++k)
    for (int ch = 0; ch < 3; ++ch) grad_direction[k] += grad_pass[ch] * jacobian.rows[ch][k];
  const T norm = math_sqrt(direction[0] * direction[0] + direction[1] * direction[1] +
                           direction[2] * direction[2]);
  const T inv = norm > T(0) ? T(1) / norm : T(0);
  visit_sh_basis<T, T>(degree, direction[0] * inv, direction[1] * inv, direction[2] * inv, [&](int b, T value) {
    for (int ch = 0; ch < 3; ++ch) {
      const T g = value * grad_pass[ch];
      grad_sh[3 * b + ch] = accumulate ? grad_sh[3 * b + ch] + g : g;
    }
  });
  if (!accumulate)  // stored coefficients of higher degrees than evaluated
    for (int k = 3 * (degree + 1) * (degree + 1); k < 3 * coefficients; ++k) grad_sh[k] = T(0);
}

// ---------------------------------------------------------------------------
// Projection (EWA splatting with a low-pass filter).

struct ProjectionSettings {
  double near_plane, far_plane;
  bool antialiased;  // Mip-Splatting: scale opacity by sqrt(det Σ2D / det(Σ2D + low-pass))
};

// Intermediate quantities of one projection, recomputed by the backward pass.
template <typename T>
struct ProjectionState {
  T cam[3];                 // camera-space mean
  T inv_z;
  T ratio_x, ratio_y;       // x/z, y/z after the frustum clamp
  bool clamped_x, clamped_y;
  T jac[6];                 // 2x3 Jacobian of the projection (J)
  T cov_cam[9];             // R Σ Rᵀ
  T s00, s01, s11;          // J Σ_cam Jᵀ before the low-pass
  T det_raw, det_blur;
  T compensation;
};

// Tangent bounds of the frustum clamp on x/z and y/z: 3DGS limits J to a
// margin around the image so that Gaussians far off-screen do not blow up.
template <typename T>
TEGA_HD void frustum_ratio_limits(const CameraParams<T>& cam, const ImageGeometry& g, T* lim_x, T* lim_y) {
  const T margin_x = T(kFrustumMargin) * T(g.width);
  const T margin_y = T(kFrustumMargin) * T(g.height);
  lim_x[0] = (T(-0.5) - margin_x - cam.cx) / cam.fx;
  lim_x[1] = (T(g.width) - T(0.5) + margin_x - cam.cx) / cam.fx;
  lim_y[0] = (T(-0.5) - margin_y - cam.cy) / cam.fy;
  lim_y[1] = (T(g.height) - T(0.5) + margin_y - cam.cy) / cam.fy;
}

// Camera-space position, Jacobian and 2D covariance. Returns false when the
// mean lies outside [near, far] or the 2D covariance is not positive definite.
template <typename T>
TEGA_HD bool project_covariance(const CameraParams<T>& cam, const ImageGeometry& g, const ProjectionSettings& s,
                                const T* mean, const T* cov6, ProjectionState<T>& st) {
  mat3_vec(cam.rotation, mean, st.cam);
  for (int k = 0; k < 3; ++k) st.cam[k] += cam.translation[k];
  const T z = st.cam[2];
  if (!(z >= T(s.near_plane) && z <= T(s.far_plane))) return false;
  st.inv_z = T(1) / z;
  T lim_x[2], lim_y[2];
  frustum_ratio_limits(cam, g, lim_x, lim_y);
  const T rx = st.cam[0] * st.inv_z, ry = st.cam[1] * st.inv_z;
  st.ratio_x = math_min(math_max(rx, lim_x[0]), lim_x[1]);
  st.ratio_y = math_min(math_max(ry, lim_y[0]), lim_y[1]);
  st.clamped_x = st.ratio_x != rx;
  st.clamped_y = st.ratio_y != ry;
  st.jac[0] = cam.fx * st.inv_z;
  st.jac[1] = T(0);
  st.jac[2] = -cam.fx * st.ratio_x * st.inv_z;
  st.jac[3] = T(0);
  st.jac[4] = cam.fy * st.inv_z;
  st.jac[5] = -cam.fy * st.ratio_y * st.inv_z;
  T cov[9];
  cov6_to_mat3(cov6, cov);
  sandwich3(cam.rotation, cov, st.cov_cam);
  // J Σ_cam Jᵀ with J's zero entries skipped.
  const T* c = st.cov_cam;
  const T* j = st.jac;
  const T m0[3] = {j[0] * c[0] + j[2] * c[6], j[0] * c[1] + j[2] * c[7], j[0] * c[2] + j[2] * c[8]};
  const T m1[3] = {j[4] * c[3] + j[5] * c[6], j[4] * c[4] + j[5] * c[7], j[4] * c[5] + j[5] * c[8]};
  st.s00 = m0[0] * j[0] + m0[2] * j[2];
  st.s01 = m0[1] * j[4] + m0[2] * j[5];
  st.s11 = m1[1] * j[4] + m1[2] * j[5];
  st.det_raw = st.s00 * st.s11 - st.s01 * st.s01;
  const T low_pass = T(kLowPassVariance);
  st.det_blur = (st.s00 + low_pass) * (st.s11 + low_pass) - st.s01 * st.s01;
  if (!(st.det_blur > T(0))) return false;
  st.compensation = T(1);
  if (s.antialiased) st.compensation = st.det_raw > T(0) ? math_sqrt(st.det_raw / st.det_blur) : T(0);
  return true;
}

// The level of q = dᵀ conic d at which opacity·G falls to kMinAlpha.
template <typename T>
TEGA_HD T splat_level(const Splat2D<T>& sp) {
  return T(2) * bound_log(sp.opacity * T(1.0 / kMinAlpha));  // the callers' margins cover its rounding
}

// Half-extents (px) of the ellipse where opacity·G ≥ kMinAlpha, and the
// tiles it touches. Returns the radius reported to callers (0 when culled).
template <typename T>
TEGA_HD int32_t splat_footprint(const Splat2D<T>& sp, const ProjectionState<T>& st, const ImageGeometry& g,
                                TileRect& rect) {
  rect = {0, 0, 0, 0};
  if (!(sp.opacity >= T(kMinAlpha))) return 0;
  const T level = splat_level(sp);
  const T low_pass = T(kLowPassVariance);
  // A small margin keeps pixels whose alpha rounds to the threshold inside.
  const T ext_x = math_sqrt(level * (st.s00 + low_pass)) + T(0.01);
  const T ext_y = math_sqrt(level * (st.s11 + low_pass)) + T(0.01);
  const T px0 = math_max(math_ceil(sp.u - ext_x), T(0)), px1 = math_min(math_floor(sp.u + ext_x), T(g.width - 1));
  const T py0 = math_max(math_ceil(sp.v - ext_y), T(0)), py1 = math_min(math_floor(sp.v + ext_y), T(g.height - 1));
  if (!(px0 <= px1 && py0 <= py1)) return 0;
  rect.x0 = int32_t(px0) / kTileSize;
  rect.x1 = int32_t(px1) / kTileSize + 1;
  rect.y0 = int32_t(py0) / kTileSize;
  rect.y1 = int32_t(py1) / kTileSize + 1;
  return int32_t(math_ceil(math_max(ext_x, ext_y)));
}

// False only when every point of the pixel-centre rectangle [x0, x1] × [y0,
// y1] lies outside the ellipse q ≤ level, so the blending skips the splat at
// every pixel there (alpha < kMinAlpha). The minimum of the convex q over the
// continuous rectangle is exact; the margin covers rounding in q, which grows
// with the size of its terms over the rectangle.
template <typename T>
TEGA_HD bool splat_may_touch(const Splat2D<T>& sp, T level, T x0, T y0, T x1, T y1) {
  const T dx0 = x0 - sp.u, dx1 = x1 - sp.u, dy0 = y0 - sp.v, dy1 = y1 - sp.v;
  if (dx0 <= T(0) && dx1 >= T(0) && dy0 <= T(0) && dy1 >= T(0)) return true;
  const T a = sp.conic_a, b = sp.conic_b, c = sp.conic_c;
  // With the centre outside, the minimum of q = a dx² + 2b dx dy + c dy²
  // lies on an edge: on x = const at dy = -b dx / c (clamped), and so on.
  // q at a point near the minimiser exceeds the minimum only to second order,
  // so approximate reciprocals do.
  const T b_over_c = b * bound_reciprocal(c), b_over_a = b * bound_reciprocal(a);
  T q_min = T(0);
  for (int e = 0; e < 4; ++e) {
    const bool vertical = e < 2;
    const T fixed = vertical ? (e == 0 ? dx0 : dx1) : (e == 2 ? dy0 : dy1);
    const T lo = vertical ? dy0 : dx0, hi = vertical ? dy1 : dx1;
    const T along_curv = vertical ? c : a, fixed_curv = vertical ? a : c;
    const T along = math_min(math_max(-fixed * (vertical ? b_over_c : b_over_a), lo), hi);
    const T q = fixed_curv * fixed * fixed + (T(2) * b * fixed + along_curv * along) * along;
    q_min = e == 0 ? q : math_min(q_min, q);
  }
  const T mx = math_max(-dx0, dx1), my = math_max(-dy0, dy1);
  const T magnitude = a * mx * mx + T(2) * (b < T(0) ? -b : b) * mx * my + c * my * my;
  return q_min <= level * T(1.001) + T(0.01) + T(1e-5) * magnitude;
}

// splat_may_touch for tile (tx, ty): its pixel centres inside the image.
template <typename T>
TEGA_HD bool splat_may_touch_tile(const Splat2D<T>& sp, T level, const ImageGeometry& g, int32_t tx, int32_t ty) {
  const int32_t x0 = tx * kTileSize, y0 = ty * kTileSize;
  const int32_t x1 = x0 + kTileSize - 1 < g.width - 1 ? x0 + kTileSize - 1 : g.width - 1;
  const int32_t y1 = y0 + kTileSize - 1 < g.height - 1 ? y0 + kTileSize - 1 : g.height - 1;
  return splat_may_touch(sp, level, T(x0), T(y0), T(x1), T(y1));
}

// Projects one Gaussian: its splat (colour excluded), tile rectangle and
// radius. Radius 0 means culled for this camera.
template <typename T>
TEGA_HD int32_t project_gaussian(const CameraParams<T>& cam, const ImageGeometry& g, const ProjectionSettings& s,
                                 const T* mean, const T* cov6, T opacity, Splat2D<T>& sp, TileRect& rect) {
  ProjectionState<T> st;
  rect = {0, 0, 0, 0};
  if (!project_covariance(cam, g, s, mean, cov6, st)) return 0;
  const T low_pass = T(kLowPassVariance);
  const T inv_det = T(1) / st.det_blur;
  sp.u = cam.fx * st.cam[0] * st.inv_z + cam.cx;
  sp.v = cam.fy * st.cam[1] * st.inv_z + cam.cy;
  sp.depth = st.cam[2];
  sp.opacity = opacity * st.compensation;
  sp.conic_a = (st.s11 + low_pass) * inv_det;
  sp.conic_b = -st.s01 * inv_det;
  sp.conic_c = (st.s00 + low_pass) * inv_det;
  sp.unused0 = T(0);
  sp.unused1 = T(0);
  return splat_footprint(sp, st, g, rect);
}

// Gradients of a projected Gaussian (held in a Splat2D: field = d loss / d
// field) back to its mean, covariance and opacity. Adds to the outputs.
template <typename T>
TEGA_HD void project_gaussian_backward(const CameraParams<T>& cam, const ImageGeometry& g,
                                       const ProjectionSettings& s, const T* mean, const T* cov6, T opacity,
                                       const Splat2D<T>& grad, T* grad_mean, T* grad_cov6, T* grad_opacity) {
  ProjectionState<T> st;
  if (!project_covariance(cam, g, s, mean, cov6, st)) return;
  const T low_pass = T(kLowPassVariance);
  const T inv_det = T(1) / st.det_blur;
  const T ca = (st.s11 + low_pass) * inv_det, cb = -st.s01 * inv_det, cc = (st.s00 + low_pass) * inv_det;

  // Opacity and the compensation factor.
  *grad_opacity += grad.opacity * st.compensation;
  const T grad_comp = grad.opacity * opacity;

  // d loss / d S (full symmetric 2x2) from the conic: dC = -C dS C.
  const T g00 = grad.conic_a, g01 = T(0.5) * grad.conic_b, g11 = grad.conic_c;
  // X = C G C with C = [[ca, cb], [cb, cc]] and G = [[g00, g01], [g01, g11]].
  const T cg00 = ca * g00 + cb * g01, cg01 = ca * g01 + cb * g11;
  const T cg10 = cb * g00 + cc * g01, cg11 = cb * g01 + cc * g11;
  T gs00 = -(cg00 * ca + cg01 * cb);
  T gs01 = -(cg00 * cb + cg01 * cc);
  T gs11 = -(cg10 * cb + cg11 * cc);
  if (s.antialiased && st.compensation > T(0)) {
    // comp = sqrt(det S / det S_b): d comp = comp/2 · tr((S⁻¹ - S_b⁻¹) dS).
    const T raw_scale = T(0.5) * grad_comp / math_sqrt(st.det_raw * st.det_blur);
    const T blur_scale = T(0.5) * grad_comp * st.compensation / st.det_blur;
    gs00 += raw_scale * st.s11 - blur_scale * (st.s11 + low_pass);
    gs11 += raw_scale * st.s00 - blur_scale * (st.s00 + low_pass);
    gs01 += -raw_scale * st.s01 + blur_scale * st.s01;
  }

  // S = J Σc Jᵀ: dΣc = Jᵀ G_S J, dJ = 2 G_S J Σc.
  const T* j = st.jac;
  const T jfull[9] = {j[0], j[1], j[2], j[3], j[4], j[5], T(0), T(0), T(0)};
  const T gs_full[9] = {gs00, gs01, T(0), gs01, gs11, T(0), T(0), T(0), T(0)};
  T grad_cov_cam[9];
  sandwich3_transposed(jfull, gs_full, grad_cov_cam);
  T grad_cov_world[9];
  sandwich3_transposed(cam.rotation, grad_cov_cam, grad_cov_world);
  T gc6[6];
  mat3_grad_to_cov6(grad_cov_world, gc6);
  for (int k = 0; k < 6; ++k) grad_cov6[k] += gc6[k];

  const T* c = st.cov_cam;
  T jc[6];  // J Σc (2x3)
  for (int r = 0; r < 2; ++r)
    for (int col = 0; col < 3; ++col)
      jc[3 * r + col] = j[3 * r] * c[col] + j[3 * r + 1] * c[3 + col] + j[3 * r + 2] * c[6 + col];
  T grad_j[6];
  for (int col = 0; col < 3; ++col) {
    grad_j[col] = T(2) * (gs00 * jc[col] + gs01 * jc[3 + col]);
    grad_j[3 + col] = T(2) * (gs01 * jc[col] + gs11 * jc[3 + col]);
  }

  // Back to the camera-space mean.
  const T x = st.cam[0], y = st.cam[1], iz = st.inv_z;
  T grad_cam[3] = {T(0), T(0), grad.depth};
  grad_cam[0] += grad.u * cam.fx * iz;
  grad_cam[1] += grad.v * cam.fy * iz;
  grad_cam[2] -= (grad.u * cam.fx * x + grad.v * cam.fy * y) * iz * iz;
  // J00 = fx/z, J11 = fy/z
  grad_cam[2] -= (grad_j[0] * cam.fx + grad_j[4] * cam.fy) * iz * iz;
  // J02 = -fx rx / z with rx = x/z unless clamped (then constant).
  grad_cam[2] += grad_j[2] * cam.fx * st.ratio_x * iz * iz;
  grad_cam[2] += grad_j[5] * cam.fy * st.ratio_y * iz * iz;
  if (!st.clamped_x) {
    const T d_j02_d_rx = -cam.fx * iz * grad_j[2];
    grad_cam[0] += d_j02_d_rx * iz;
    grad_cam[2] -= d_j02_d_rx * x * iz * iz;
  }
  if (!st.clamped_y) {
    const T d_j12_d_ry = -cam.fy * iz * grad_j[5];
    grad_cam[1] += d_j12_d_ry * iz;
    grad_cam[2] -= d_j12_d_ry * y * iz * iz;
  }
  T gm[3];
  mat3t_vec(cam.rotation, grad_cam, gm);
  for (int k = 0; k < 3; ++k) grad_mean[k] += gm[k];
  (void)g;
}

// ---------------------------------------------------------------------------
// Per-pixel blending, front to back.

// Alpha of a splat at pixel (px, py), before the kMinAlpha test.
template <typename T>
TEGA_HD T splat_alpha(const Splat2D<T>& sp, T px, T py, T& gaussian) {
  const T dx = px - sp.u, dy = py - sp.v;
  const T power = T(-0.5) * (sp.conic_a * dx * dx + sp.conic_c * dy * dy) - sp.conic_b * dx * dy;
  gaussian = math_exp(power);
  return math_min(T(kMaxAlpha), sp.opacity * gaussian);
}

// Running state of one pixel in the forward pass.
template <typename T>
struct PixelAccumulator {
  T transmittance = T(1);
  T rgb[3] = {T(0), T(0), T(0)};
  T depth = T(0);
  int32_t last = 0;  // 1 + index of the last splat blended, within the tile's list
  bool done = false;
};

// Blends splat number `index` into the pixel; sets done once the
// transmittance would fall under kMinTransmittance (that splat not blended).
template <typename T>
TEGA_HD void blend_forward(PixelAccumulator<T>& acc, const Splat2D<T>& sp, T px, T py, int32_t index) {
  T gaussian;
  const T alpha = splat_alpha(sp, px, py, gaussian);
  if (alpha < T(kMinAlpha)) return;
  const T next = acc.transmittance * (T(1) - alpha);
  if (next < T(kMinTransmittance)) {
    acc.done = true;
    return;
  }
  const T w = alpha * acc.transmittance;
  acc.rgb[0] += w * sp.red;
  acc.rgb[1] += w * sp.green;
  acc.rgb[2] += w * sp.blue;
  acc.depth += w * sp.depth;
  acc.transmittance = next;
  acc.last = index + 1;
}

// The expected depth Σ w z / alpha of a pixel, 0 where alpha is too small
// to divide by.
template <typename T>
TEGA_HD T expected_depth(T weighted_depth, T alpha) {
  return alpha > T(kMinDepthAlpha) ? weighted_depth / alpha : T(0);
}

// Backward of expected_depth: from d loss / d depth, returns d loss / d Σ w z
// and adds d loss / d alpha to grad_alpha.
template <typename T>
TEGA_HD T expected_depth_backward(T grad_depth, T depth, T alpha, T& grad_alpha) {
  if (!(alpha > T(kMinDepthAlpha))) return T(0);
  const T inv_alpha = T(1) / alpha;
  grad_alpha -= grad_depth * depth * inv_alpha;
  return grad_depth * inv_alpha;
}

// Per-pixel state of the backward pass, walking the blended splats back to
// front: T of the current splat is recovered as T_next / (1 - alpha).
template <typename T>
struct PixelBackward {
  T grad_rgb[3], grad_alpha_out, grad_depth;
  T final_transmittance;
  T transmittance;            // T after the current splat
  T behind_rgb[3] = {T(0), T(0), T(0)};  // colour of everything behind, per unit transmittance
  T behind_depth = T(0);
  T background_dot;           // bg · dL/drgb
};

// Gradient of one splat's fields at one pixel, added to `grad`. Returns
// false when the splat was skipped at this pixel (alpha < kMinAlpha).
template <typename T>
TEGA_HD bool blend_backward(PixelBackward<T>& st, const Splat2D<T>& sp, T px, T py, Splat2D<T>& grad) {
  const T dx = px - sp.u, dy = py - sp.v;
  const T power = T(-0.5) * (sp.conic_a * dx * dx + sp.conic_c * dy * dy) - sp.conic_b * dx * dy;
  const T gaussian = math_exp(power);
  const T raw_alpha = sp.opacity * gaussian;
  const T alpha = math_min(T(kMaxAlpha), raw_alpha);
  if (alpha < T(kMinAlpha)) return false;
  const T one_minus = T(1) - alpha;
  const T inv_one_minus = T(1) / one_minus;
  st.transmittance = st.transmittance * inv_one_minus;  // T before this splat
  const T t = st.transmittance;
  const T w = alpha * t;
  grad.red += w * st.grad_rgb[0];
  grad.green += w * st.grad_rgb[1];
  grad.blue += w * st.grad_rgb[2];
  grad.depth += w * st.grad_depth;
  const T colour[3] = {sp.red, sp.green, sp.blue};
  T grad_a = T(0);
  for (int ch = 0; ch < 3; ++ch) grad_a += (colour[ch] - st.behind_rgb[ch]) * st.grad_rgb[ch];
  grad_a += (sp.depth - st.behind_depth) * st.grad_depth;
  grad_a *= t;
  const T final_over = st.final_transmittance * inv_one_minus;
  grad_a += final_over * (st.grad_alpha_out - st.background_dot);
  for (int ch = 0; ch < 3; ++ch) st.behind_rgb[ch] = alpha * colour[ch] + one_minus * st.behind_rgb[ch];
  st.behind_depth = alpha * sp.depth + one_minus * st.behind_depth;
  if (raw_alpha > T(kMaxAlpha)) return true;  // clamped: no gradient to opacity or shape
  grad.opacity += gaussian * grad_a;
  const T grad_power = raw_alpha * grad_a;
  // power = -½(a dx² + c dy²) - b dx dy, with dx = px - u.
  grad.u += grad_power * (sp.conic_a * dx + sp.conic_b * dy);
  grad.v += grad_power * (sp.conic_b * dx + sp.conic_c * dy);
  grad.conic_a += T(-0.5) * grad_power * dx * dx;
  grad.conic_b += -grad_power * dx * dy;
  grad.conic_c += T(-0.5) * grad_power * dy * dy;
  return true;
}

}  // namespace tega::splat
