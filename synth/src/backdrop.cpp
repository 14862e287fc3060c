#include <algorithm>
#include <cmath>

#include "tega/synth/backdrop.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

constexpr double kRadius = 3.0;        // metres, around the world origin
constexpr double kPanelWidth = 0.35;   // radians of azimuth between seams
constexpr double kFloorElevation = -0.35;
constexpr int kTapeMarks = 14;

}  // namespace

Backdrop::Backdrop(uint64_t seed) : seed_(hash_of(seed, 0xbacd)) {}

Eigen::Vector3f Backdrop::colour(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  // Where the ray leaves the sphere (the origin is inside it).
  const double b = origin.dot(direction), c = origin.squaredNorm() - kRadius * kRadius;
  const Eigen::Vector3d hit = origin + (-b + std::sqrt(b * b - c)) * direction;
  const double azimuth = std::atan2(hit.x(), -hit.z());  // 0 straight behind the head
  const double elevation = std::asin(std::clamp(hit.y() / kRadius, -1.0, 1.0));

  if (elevation < kFloorElevation) {
    const double n = value_noise(seed_ + 1, hit.x() * 6, hit.z() * 6);
    return Eigen::Vector3f(0.22f, 0.21f, 0.20f) * float(0.85 + 0.3 * n);
  }
  Eigen::Vector3f col(0.40f, 0.43f, 0.47f);
  col *= float(0.8 + 0.25 * smoothstep(kFloorElevation, 0.8, elevation));    // light falls off downwards
  col *= float(0.9 + 0.2 * value_noise(seed_ + 2, azimuth * 12, elevation * 12));  // uneven fabric
  const double weave = std::sin(azimuth * 900) * std::sin(elevation * 900);
  col *= float(1.0 + 0.04 * weave);
  const double seam = std::abs(std::remainder(azimuth, kPanelWidth));
  if (seam < 0.004) col *= 0.7f;
  for (int i = 0; i < kTapeMarks; ++i) {
    // Crosses of coloured tape, as studios put on backdrops for tracking.
    const double ma = (uniform(seed_, i, 0) - 0.5) * 2.4, me = (uniform(seed_, i, 1) - 0.5) * 1.0;
    const double da = std::abs(azimuth - ma), de = std::abs(elevation - me);
    if ((da < 0.03 && de < 0.004) || (de < 0.03 && da < 0.004)) {
      const double hue = uniform(seed_, i, 2);
      col = hue < 0.33 ? Eigen::Vector3f(0.8f, 0.25f, 0.2f)
                       : hue < 0.66 ? Eigen::Vector3f(0.2f, 0.6f, 0.3f) : Eigen::Vector3f(0.85f, 0.8f, 0.2f);
    }
  }
  return col;
}

ImageF Backdrop::render(const Camera& camera) const {
  ImageF out(camera.width, camera.height, 3);
  const Eigen::Vector3d centre = camera.center();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3f c = colour(centre, camera.ray_direction(Eigen::Vector2d(x, y)));
      for (int k = 0; k < 3; ++k) out.at(x, y, k) = c[k];
    }
  }
  return out;
}

}  // namespace tega::synth
