#include "tega/synth/shadow_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "tega/core/error.h"
#include "tega/synth/ground_truth_depth.h"

namespace tega::synth {
namespace {

constexpr double kLightDistance = 50.0;  // metres from the mesh's centre to the shadow camera
constexpr double kDepthBiasTexels = 1.0;  // faceting and curvature within one filter footprint
// Steepest receiver plane followed (depth change per lateral metre); beyond
// it the surface is nearly edge-on to the light and its Lambert term ~0.
constexpr double kMaxReceiverSlope = 12.0;
constexpr int kMaxTaps = 7;  // per axis

// World-to-camera rotation of a camera looking along -towards_light (OpenCV
// axes: rows are the camera's x, y, z in world coordinates).
Eigen::Matrix3d looking_along(const Eigen::Vector3d& towards_light) {
  const Eigen::Vector3d z = -towards_light.normalized();
  const Eigen::Vector3d helper = std::abs(z.y()) < 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = helper.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return R;
}

}  // namespace

ShadowMap::ShadowMap(const Vertices& positions, const Triangles& faces, const Eigen::Vector3f& towards_light,
                     int size, double softness_m) {
  if (size < 2) throw Error("shadow map: size must be at least 2");
  if (positions.rows() == 0) throw Error("shadow map: the mesh has no vertices");
  const Eigen::Vector3d lo = positions.colwise().minCoeff().cast<double>().transpose();
  const Eigen::Vector3d hi = positions.colwise().maxCoeff().cast<double>().transpose();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double radius = 0;
  for (int v = 0; v < positions.rows(); ++v)
    radius = std::max(radius, (positions.row(v).cast<double>().transpose() - centre).norm());
  radius = std::max(radius, 1e-6);

  const Eigen::Vector3d light = towards_light.cast<double>().normalized();
  camera_.name = "shadow";
  camera_.width = camera_.height = size;
  rotation_ = looking_along(light);
  const Eigen::Vector3d eye = centre + kLightDistance * light;
  translation_ = -rotation_ * eye;
  camera_.world_to_camera.R = rotation_;
  camera_.world_to_camera.t = translation_;
  // The bounding sphere's nearest cross-section fills the map, half a texel to spare.
  const double focal = (0.5 * size - 1.0) * (kLightDistance - radius) / radius;
  camera_.K << focal, 0, 0.5 * (size - 1), 0, focal, 0.5 * (size - 1), 0, 0, 1;
  texel_m_ = kLightDistance / focal;
  depth_ = render_depth(camera_, positions, faces);

  const double radius_texels = std::max(1.0, softness_m / texel_m_);
  taps_ = std::clamp(static_cast<int>(std::ceil(radius_texels)) + 1, 2, kMaxTaps);
  tap_spacing_ = 2 * radius_texels / (taps_ - 1);
}

float ShadowMap::visibility(const Eigen::Vector3f& point, const Eigen::Vector3f& normal) const {
  const Eigen::Vector3d q = rotation_ * point.cast<double>() + translation_;  // camera space
  if (q.z() <= 0) return 1.0f;
  const double fx = camera_.K(0, 0), cx = camera_.K(0, 2), cy = camera_.K(1, 2);
  const double u = fx * q.x() / q.z() + cx, v = fx * q.y() / q.z() + cy;
  const double metres_per_texel = q.z() / fx;
  // The receiver's tangent plane: depth change per metre along camera x and y.
  const Eigen::Vector3d n = rotation_ * normal.cast<double>();
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  if (n.z() < 0) {
    slope = -n.head<2>() / n.z();
    if (slope.norm() > kMaxReceiverSlope) slope *= kMaxReceiverSlope / slope.norm();
  }
  const double bias = kDepthBiasTexels * metres_per_texel;
  const int W = depth_.width, H = depth_.height;
  const auto lit_texel = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= W || j >= H) return 1.0;
    const float occluder = depth_.at(i, j, 0);
    if (occluder <= 0) return 1.0;
    const double receiver = q.z() + metres_per_texel * (slope.x() * (i - u) + slope.y() * (j - v));
    return receiver - bias <= occluder ? 1.0 : 0.0;
  };

  double lit = 0;
  const double first = -0.5 * tap_spacing_ * (taps_ - 1);
  for (int b = 0; b < taps_; ++b) {
    const double y = v + first + b * tap_spacing_;
    const int j = static_cast<int>(std::floor(y));
    const double wy = y - j;
    for (int a = 0; a < taps_; ++a) {
      const double x = u + first + a * tap_spacing_;
      const int i = static_cast<int>(std::floor(x));
      const double wx = x - i;
      lit += (1 - wy) * ((1 - wx) * lit_texel(i, j) + wx * lit_texel(i + 1, j)) +
             wy * ((1 - wx) * lit_texel(i, j + 1) + wx * lit_texel(i + 1, j + 1));
    }
  }
  return static_cast<float>(lit / (taps_ * taps_));
}

}  // namespace tega::synth
