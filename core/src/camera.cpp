#include "tega/core/camera.h"

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "tega/core/error.h"

namespace tega {
namespace {

// Newton's method converges quadratically, so a handful of steps reach
// double precision; the cap only stops points where distort() folds over.
constexpr int kMaxUndistortSteps = 50;

// Distorted normalised coordinates of a pixel: K^-1 (u, v, 1) for an upper
// triangular K with K(2,2) = 1.
Eigen::Vector2d pixel_to_normalised(const Eigen::Matrix3d& K, const Eigen::Vector2d& pixel) {
  const double y = (pixel.y() - K(1, 2)) / K(1, 1);
  const double x = (pixel.x() - K(0, 2) - K(0, 1) * y) / K(0, 0);
  return {x, y};
}

Eigen::Vector2d normalised_to_pixel(const Eigen::Matrix3d& K, const Eigen::Vector2d& p) {
  return {K(0, 0) * p.x() + K(0, 1) * p.y() + K(0, 2), K(1, 1) * p.y() + K(1, 2)};
}

}  // namespace

Eigen::Vector3d Camera::center() const {
  return -world_to_camera.R.transpose() * world_to_camera.t;
}

Eigen::Vector2d Camera::distort(const Eigen::Vector2d& undistorted) const {
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double x = undistorted.x(), y = undistorted.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d Camera::undistort(const Eigen::Vector2d& distorted) const {
  if (!has_distortion()) return distorted;
  const auto [k1, k2, p1, p2, k3] = distortion;
  Eigen::Vector2d p = distorted;
  for (int step = 0; step < kMaxUndistortSteps; ++step) {
    const double x = p.x(), y = p.y();
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * k3 * r2);
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * p1 * y + 6 * p2 * x;
    J(0, 1) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 0) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * p1 * y + 2 * p2 * x;
    const Eigen::Vector2d delta = J.inverse() * (distort(p) - distorted);
    if (!delta.allFinite()) break;
    p -= delta;
    if (delta.norm() <= 4 * std::numeric_limits<double>::epsilon() * (1 + p.norm())) break;
  }
  return p;
}

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d c = world_to_camera.apply(world);
  if (!(c.z() > 0)) return std::nullopt;
  return normalised_to_pixel(K, distort(c.head<2>() / c.z()));
}

Eigen::Matrix<double, 2, 3> Camera::projection_jacobian(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d c = world_to_camera.apply(world);
  const double x = c.x() / c.z(), y = c.y() / c.z();
  Eigen::Matrix<double, 2, 3> normalised_by_camera;
  normalised_by_camera << 1 / c.z(), 0, -x / c.z(), 0, 1 / c.z(), -y / c.z();
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double radial_by_r2 = k1 + r2 * (2 * k2 + 3 * r2 * k3);
  Eigen::Matrix2d distorted_by_normalised;
  distorted_by_normalised << radial + 2 * x * x * radial_by_r2 + 2 * p1 * y + 6 * p2 * x,
      2 * x * y * radial_by_r2 + 2 * p1 * x + 2 * p2 * y,  //
      2 * x * y * radial_by_r2 + 2 * p1 * x + 2 * p2 * y,
      radial + 2 * y * y * radial_by_r2 + 6 * p1 * y + 2 * p2 * x;
  return K.topLeftCorner<2, 2>() * distorted_by_normalised * normalised_by_camera * world_to_camera.R;
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector2d& pixel, double depth) const {
  const Eigen::Vector2d p = undistort(pixel_to_normalised(K, pixel));
  return world_to_camera.inverse().apply(Eigen::Vector3d(p.x() * depth, p.y() * depth, depth));
}

Eigen::Vector3d Camera::ray_direction(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d p = undistort(pixel_to_normalised(K, pixel));
  return world_to_camera.R.transpose() * Eigen::Vector3d(p.x(), p.y(), 1).normalized();
}

bool Camera::has_distortion() const {
  for (double c : distortion)
    if (c != 0) return true;
  return false;
}

UndistortionMaps Camera::undistortion_maps() const {
  UndistortionMaps maps;
  maps.width = width;
  maps.height = height;
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  maps.map_x.resize(count);
  maps.map_y.resize(count);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector2d source = normalised_to_pixel(K, distort(pixel_to_normalised(K, {u, v})));
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u);
      maps.map_x[i] = static_cast<float>(source.x());
      maps.map_y[i] = static_cast<float>(source.y());
    }
  }
  return maps;
}

Camera Camera::scaled(double factor) const {
  if (!(factor > 0) || !std::isfinite(factor))
    throw Error("camera '" + name + "': scale factor must be positive, got " +
                std::to_string(factor));
  Camera out = *this;
  out.width = static_cast<int>(std::lround(factor * width));
  out.height = static_cast<int>(std::lround(factor * height));
  out.K.row(0) *= factor;
  out.K.row(1) *= factor;
  out.K(0, 2) = factor * (K(0, 2) + 0.5) - 0.5;
  out.K(1, 2) = factor * (K(1, 2) + 0.5) - 0.5;
  return out;
}

}  // namespace tega
