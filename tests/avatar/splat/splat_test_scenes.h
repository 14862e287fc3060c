#pragma once
// Random test scenes for the rasterizer tests, and a brute-force reference
// renderer written independently of the rasterizer: every Gaussian is
// evaluated at every pixel, then the contributions are sorted by depth.

#include <tega/splat/rasterize.h>

#include <ATen/ATen.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <vector>

namespace tega::splat::test {

enum class ColorMode { kSh, kRgb, kPerCameraRgb };

struct SceneSpec {
  int64_t gaussians = 24;
  int cameras = 3;
  int width = 45, height = 37;  // not multiples of the tile size
  ColorMode colors = ColorMode::kSh;
  int sh_degree = 3;
  int sh_coefficients = 16;
  bool antialiased = false;
  double max_opacity = 0.95;
  double min_scale = 0.04, max_scale = 0.2;  // metres; the cameras see about 2 m across
  double spread = 0.7;                        // means uniform in [-spread, spread]³
  uint64_t seed = 1;
};

// How GoogleTest names a scene in parameterised tests (ctest lists them by
// it): its defining choices, instead of the struct's raw bytes.
inline void PrintTo(const SceneSpec& spec, std::ostream* out) {
  const char* colors = spec.colors == ColorMode::kSh ? "sh" : spec.colors == ColorMode::kRgb ? "rgb" : "camera_rgb";
  *out << colors;
  if (spec.colors == ColorMode::kSh) *out << spec.sh_degree;
  *out << (spec.antialiased ? "_antialiased" : "") << "_" << spec.gaussians << "_gaussians_seed" << spec.seed;
}

struct Scene {
  at::Tensor means, covariances, colors, opacities, background;
  std::vector<RasterCamera> cameras;
  RasterSettings settings;

  std::vector<at::Tensor> inputs() const { return {means, covariances, colors, opacities, background}; }
  Scene to(at::ScalarType dtype, at::Device device = at::kCPU) const {
    Scene s = *this;
    for (at::Tensor* t : {&s.means, &s.covariances, &s.colors, &s.opacities, &s.background})
      *t = t->to(device, dtype).detach().contiguous();
    return s;
  }
  RasterOutput render(const MeanGradientStats* stats = nullptr) const {
    return rasterize(means, covariances, colors, opacities, background, cameras, settings, stats);
  }
};

// Camera at `eye` looking at the origin, OpenCV axes (y down).
inline RasterCamera look_at_origin(const Eigen::Vector3d& eye, double focal, int width, int height, double cx_shift) {
  const Eigen::Vector3d z = (-eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d(0, -1, 0).cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.row(0) = x;
  r.row(1) = y;
  r.row(2) = z;
  const Eigen::Vector3d t = -r * eye;
  RasterCamera cam;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) cam.rotation[3 * i + k] = r(i, k);
    cam.translation[i] = t[i];
  }
  cam.fx = focal;
  cam.fy = focal * 1.05;
  cam.cx = 0.5 * (width - 1) + cx_shift;
  cam.cy = 0.5 * (height - 1) - 0.5 * cx_shift;
  return cam;
}

// Double-precision scene; Gaussians straddle the image borders, several
// overlap many tiles, and one sits behind the first camera.
inline Scene random_scene(const SceneSpec& spec) {
  at::manual_seed(spec.seed);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const int64_t n = spec.gaussians;
  Scene s;
  s.means = (at::rand({n, 3}, opts) * 2 - 1) * spec.spread;
  const at::Tensor scales = spec.min_scale + at::rand({n, 3}, opts) * (spec.max_scale - spec.min_scale);
  const at::Tensor quats = at::randn({n, 4}, opts);
  s.covariances = covariance_from_scale_rotation(scales, quats);
  s.opacities = 0.05 + at::rand({n}, opts) * (spec.max_opacity - 0.05);
  s.background = at::rand({3}, opts);
  switch (spec.colors) {
    case ColorMode::kSh:
      s.colors = at::randn({n, spec.sh_coefficients, 3}, opts) * 0.3;
      s.colors.select(1, 0).add_(0.4);
      break;
    case ColorMode::kRgb:
      s.colors = at::rand({n, 3}, opts);
      break;
    case ColorMode::kPerCameraRgb:
      s.colors = at::rand({spec.cameras, n, 3}, opts);
      break;
  }
  const double focal = 0.6 * spec.width;
  for (int c = 0; c < spec.cameras; ++c) {
    const double angle = 0.6 * c - 0.5;
    const Eigen::Vector3d eye(2.4 * std::sin(angle), 0.3 * c - 0.2, -2.4 * std::cos(angle));
    s.cameras.push_back(look_at_origin(eye, focal, spec.width, spec.height, 1.5 * c - 1.0));
  }
  // Behind camera 0: culled there, possibly visible to the others.
  {
    const RasterCamera& cam = s.cameras[0];
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = cam.rotation[i];
    const Eigen::Vector3d t(cam.translation[0], cam.translation[1], cam.translation[2]);
    const Eigen::Vector3d behind = r.transpose() * (Eigen::Vector3d(0.1, 0.0, -0.5) - t);
    for (int k = 0; k < 3; ++k) s.means[n - 1][k] = behind[k];
  }
  s.settings.width = spec.width;
  s.settings.height = spec.height;
  s.settings.near_plane = 0.2;
  s.settings.far_plane = 20.0;
  s.settings.antialiased = spec.antialiased;
  s.settings.sh_degree = spec.sh_degree;
  s.settings.per_camera_rgb = spec.colors == ColorMode::kPerCameraRgb;
  return s;
}

// ---------------------------------------------------------------------------
// Brute-force reference.

inline double sh_colour_reference(const double* sh, int degree, const Eigen::Vector3d& dir, int channel) {
  const Eigen::Vector3d d = dir.normalized();
  const double x = d.x(), y = d.y(), z = d.z();
  std::vector<double> basis = {0.28209479177387814};
  if (degree >= 1) {
    const double c1 = 0.4886025119029199;
    basis.insert(basis.end(), {-c1 * y, c1 * z, -c1 * x});
  }
  if (degree >= 2)
    basis.insert(basis.end(), {1.0925484305920792 * x * y, -1.0925484305920792 * y * z,
                               0.31539156525252005 * (2 * z * z - x * x - y * y), -1.0925484305920792 * x * z,
                               0.5462742152960396 * (x * x - y * y)});
  if (degree >= 3)
    basis.insert(basis.end(), {-0.5900435899266435 * y * (3 * x * x - y * y), 2.890611442640554 * x * y * z,
                               -0.4570457994644658 * y * (4 * z * z - x * x - y * y),
                               0.3731763325901154 * z * (2 * z * z - 3 * x * x - 3 * y * y),
                               -0.4570457994644658 * x * (4 * z * z - x * x - y * y),
                               1.445305721320277 * z * (x * x - y * y),
                               -0.5900435899266435 * x * (x * x - 3 * y * y)});
  double value = 0.5;
  for (std::size_t b = 0; b < basis.size(); ++b) value += basis[b] * sh[3 * b + channel];
  return std::max(value, 0.0);
}

struct ReferenceImages {
  std::vector<double> rgb, alpha, depth;  // [C,H,W,3], [C,H,W], expected depth [C,H,W]
};

inline ReferenceImages reference_render(const Scene& scene) {
  const Scene s = scene.to(at::kDouble);
  const int64_t n = s.means.size(0);
  const int w = s.settings.width, h = s.settings.height;
  const auto C = int(s.cameras.size());
  ReferenceImages out;
  out.rgb.assign(std::size_t(C) * h * w * 3, 0.0);
  out.alpha.assign(std::size_t(C) * h * w, 0.0);
  out.depth.assign(std::size_t(C) * h * w, 0.0);
  const double* means = s.means.data_ptr<double>();
  const double* covs = s.covariances.data_ptr<double>();
  const double* colors = s.colors.data_ptr<double>();
  const double* opac = s.opacities.data_ptr<double>();
  const double* bg = s.background.data_ptr<double>();
  const bool sh = s.colors.dim() == 3 && !s.settings.per_camera_rgb;
  const int64_t k = sh ? s.colors.size(1) : 0;

  struct Projected {
    double z, u, v, opacity;
    Eigen::Matrix2d conic;
    double rgb[3];
    int64_t index;
  };
  for (int c = 0; c < C; ++c) {
    const RasterCamera& cam = s.cameras[c];
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = cam.rotation[i];
    const Eigen::Vector3d t(cam.translation[0], cam.translation[1], cam.translation[2]);
    const Eigen::Vector3d centre = -r.transpose() * t;
    std::vector<Projected> projected;
    for (int64_t g = 0; g < n; ++g) {
      const Eigen::Vector3d m(means[3 * g], means[3 * g + 1], means[3 * g + 2]);
      const Eigen::Vector3d p = r * m + t;
      if (p.z() < s.settings.near_plane || p.z() > s.settings.far_plane) continue;
      // Jacobian of the perspective projection, with x/z and y/z held inside
      // the image widened by 15% on each side.
      const double mx = 0.15 * w, my = 0.15 * h;
      const double rx = std::clamp(p.x() / p.z(), (-0.5 - mx - cam.cx) / cam.fx, (w - 0.5 + mx - cam.cx) / cam.fx);
      const double ry = std::clamp(p.y() / p.z(), (-0.5 - my - cam.cy) / cam.fy, (h - 0.5 + my - cam.cy) / cam.fy);
      Eigen::Matrix<double, 2, 3> j;
      j << cam.fx / p.z(), 0, -cam.fx * rx / p.z(), 0, cam.fy / p.z(), -cam.fy * ry / p.z();
      const double* cv = covs + 6 * g;
      Eigen::Matrix3d sigma;
      sigma << cv[0], cv[1], cv[2], cv[1], cv[3], cv[4], cv[2], cv[4], cv[5];
      const Eigen::Matrix2d cov2 = j * r * sigma * r.transpose() * j.transpose();
      const Eigen::Matrix2d blurred = cov2 + 0.3 * Eigen::Matrix2d::Identity();
      double opacity = opac[g];
      if (s.settings.antialiased) opacity *= std::sqrt(std::max(cov2.determinant(), 0.0) / blurred.determinant());
      Projected pr{p.z(), cam.fx * p.x() / p.z() + cam.cx, cam.fy * p.y() / p.z() + cam.cy, opacity,
                   blurred.inverse(), {0, 0, 0}, g};
      for (int ch = 0; ch < 3; ++ch) {
        if (sh)
          pr.rgb[ch] = sh_colour_reference(colors + 3 * k * g, s.settings.sh_degree, m - centre, ch);
        else if (s.settings.per_camera_rgb)
          pr.rgb[ch] = colors[(c * n + g) * 3 + ch];
        else
          pr.rgb[ch] = colors[3 * g + ch];
      }
      projected.push_back(pr);
    }
    std::stable_sort(projected.begin(), projected.end(),
                     [](const Projected& a, const Projected& b) { return a.z < b.z; });
    for (int py = 0; py < h; ++py)
      for (int px = 0; px < w; ++px) {
        double transmittance = 1, rgb[3] = {0, 0, 0}, depth = 0;
        for (const Projected& pr : projected) {
          const Eigen::Vector2d d(px - pr.u, py - pr.v);
          const double alpha = std::min(0.99, pr.opacity * std::exp(-0.5 * d.dot(pr.conic * d)));
          if (alpha < 1.0 / 255.0) continue;
          if (transmittance * (1 - alpha) < 1e-4) break;
          for (int ch = 0; ch < 3; ++ch) rgb[ch] += transmittance * alpha * pr.rgb[ch];
          depth += transmittance * alpha * pr.z;
          transmittance *= 1 - alpha;
        }
        const std::size_t pixel = (std::size_t(c) * h + py) * w + px;
        for (int ch = 0; ch < 3; ++ch) out.rgb[3 * pixel + ch] = rgb[ch] + transmittance * bg[ch];
        out.alpha[pixel] = 1 - transmittance;
        out.depth[pixel] = out.alpha[pixel] > 1e-10 ? depth / out.alpha[pixel] : 0.0;
      }
  }
  return out;
}

inline std::vector<double> to_vector(const at::Tensor& t) {
  const at::Tensor d = t.detach().to(at::kCPU, at::kDouble).contiguous();
  return std::vector<double>(d.data_ptr<double>(), d.data_ptr<double>() + d.numel());
}

inline double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = a.size() == b.size() ? 0.0 : INFINITY;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

// ‖a − b‖ / ‖b‖.
inline double relative_error(const at::Tensor& a, const at::Tensor& b) {
  const at::Tensor ad = a.detach().to(at::kCPU, at::kDouble), bd = b.detach().to(at::kCPU, at::kDouble);
  return (ad - bd).norm().item<double>() / std::max(bd.norm().item<double>(), 1e-30);
}

}  // namespace tega::splat::test
