#pragma once
// Pinhole camera with OpenCV's 5-parameter distortion (k1, k2, p1, p2, k3).
// Conventions (same as OpenCV): world-to-camera extrinsics, camera looks down
// +z with +x right and +y down, pixel (0,0) is the centre of the top-left
// pixel. Units: metres.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "tega/core/geometry.h"

namespace tega {

// For every pixel of the undistorted image, where to sample the distorted
// (captured) image. Same meaning as cv::initUndistortRectifyMap with newK = K
// and R = I: undistorted(u, v) = captured(map_x[i], map_y[i]), i = v * width + u.
struct UndistortionMaps {
  int width = 0, height = 0;
  std::vector<float> map_x, map_y;  // row-major, width * height each
};

struct Camera {
  std::string name;
  int width = 0, height = 0;
  // Upper triangular with K(2,2) = 1: [fx s cx; 0 fy cy; 0 0 1] (s, the skew, is
  // usually 0). Rig::validate() enforces this shape.
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3
  RigidTransform world_to_camera;

  Eigen::Vector3d center() const;  // camera centre in world coordinates

  // Normalised image coordinates (x/z, y/z) <-> distorted normalised coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& undistorted) const;
  // Inverse of distort() by Newton iteration, run to convergence: exact to
  // ~1e-12 wherever distort() is invertible (the mild distortion of real
  // lenses, over and beyond the image).
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;

  // World point -> pixel, with distortion. nullopt when the point is not in
  // front of the camera (z <= 0). The pixel may lie outside the image.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& world) const;
  // d project(world) / d world, analytic (distortion included), for
  // Gauss-Newton solvers. Requires the point in front of the camera.
  Eigen::Matrix<double, 2, 3> projection_jacobian(const Eigen::Vector3d& world) const;
  // Pixel + depth along the camera's z axis -> world point (inverse of project()).
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel, double depth) const;
  // Unit-length world-space direction of the ray through a (distorted) pixel.
  Eigen::Vector3d ray_direction(const Eigen::Vector2d& pixel) const;

  bool has_distortion() const;  // any coefficient non-zero
  UndistortionMaps undistortion_maps() const;

  // The same camera for an image resized by `factor` (0.5 = half size), with
  // pixel centres kept consistent: a pixel x maps to factor * (x + 0.5) - 0.5,
  // so fx' = factor fx and cx' = factor (cx + 0.5) - 0.5 (likewise y). The size
  // becomes round(factor * size). Throws tega::Error unless factor > 0.
  Camera scaled(double factor) const;
};

}  // namespace tega
