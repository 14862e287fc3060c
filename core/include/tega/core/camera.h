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
// (captured) image. Same meaning as cv::initUndistortRectifyMap with newK = K.
struct UndistortionMaps {
  int width = 0, height = 0;
  std::vector<float> map_x, map_y;  // row-major, width * height each
};

struct Camera {
  std::string name;
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3
  RigidTransform world_to_camera;

  Eigen::Vector3d center() const;  // camera centre in world coordinates

  // Normalised image coordinates (x/z, y/z) <-> distorted normalised coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& undistorted) const;
  // Inverse of distort() by fixed-point iteration; exact to ~1e-12 for the
  // mild distortion of real lenses.
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;

  // World point -> pixel, with distortion. nullopt when the point is not in
  // front of the camera (z <= 0). The pixel may lie outside the image.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& world) const;
  // Pixel + depth along the camera's z axis -> world point (inverse of project()).
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel, double depth) const;
  // Unit-length world-space direction of the ray through a (distorted) pixel.
  Eigen::Vector3d ray_direction(const Eigen::Vector2d& pixel) const;

  bool has_distortion() const;
  UndistortionMaps undistortion_maps() const;

  // The same camera for an image resized by `factor` (0.5 = half size), with
  // pixel centres kept consistent: K' = S K with the half-pixel shift.
  Camera scaled(double factor) const;
};

}  // namespace tega
