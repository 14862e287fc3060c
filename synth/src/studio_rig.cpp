#include <cmath>
#include <numbers>

#include "tega/core/error.h"
#include "tega/synth/random.h"
#include "tega/synth/studio_rig.h"

namespace tega::synth {
namespace {

constexpr uint64_t kStudioSeed = 0x5741d10;  // fixed: lens variations belong to the studio
constexpr double kVerticalSquash = 0.7;      // studios spread cameras wider than tall
constexpr double kAimJitterRad = 0.01;

std::string camera_name(int index, int count) {
  std::string digits = std::to_string(index);
  const size_t width = count > 100 ? 3 : 2;
  if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
  return "cam" + digits;
}

// Signed uniform in [-1, 1) for one property of one camera.
double jitter(int camera, int property) { return 2.0 * uniform(kStudioSeed, camera, property) - 1.0; }

}  // namespace

Rig make_studio_rig(const StudioOptions& o) {
  if (o.cameras < 1) throw Error("studio.cameras must be at least 1");
  if (o.width < 8 || o.height < 8) throw Error("studio.width and studio.height must be at least 8 pixels");
  if (o.distortion.size() != 5) throw Error("studio.distortion must list 5 coefficients: k1, k2, p1, p2, k3");
  if (o.focal_length_mm <= 0 || o.sensor_width_mm <= 0 || o.distance_m <= 0)
    throw Error("studio.focal_length_mm, sensor_width_mm and distance_m must be positive");

  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double cap_cos = std::cos(o.cap_half_angle_deg * std::numbers::pi / 180.0);
  const double f_px = o.focal_length_mm / o.sensor_width_mm * o.width;

  Rig rig;
  for (int i = 0; i < o.cameras; ++i) {
    // Camera 0 looks straight at the face; the others spiral outwards.
    const double cos_theta = i == 0 ? 1.0 : 1.0 - (i - 0.5) / std::max(1, o.cameras - 1) * (1.0 - cap_cos);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = i * golden_angle;
    const Eigen::Vector3d direction =
        Eigen::Vector3d(sin_theta * std::cos(phi), kVerticalSquash * sin_theta * std::sin(phi), cos_theta).normalized();
    const Eigen::Vector3d centre = o.distance_m * direction;

    // OpenCV axes: z forward (to the origin), x right, y down; world +y is up.
    Eigen::Vector3d forward = -direction;
    const Eigen::Vector3d aim(jitter(i, 0), jitter(i, 1), 0);
    forward = (forward + kAimJitterRad * aim).normalized();
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitY()).normalized();
    const Eigen::Vector3d down = forward.cross(right);

    Camera cam;
    cam.name = camera_name(i, o.cameras);
    cam.width = o.width;
    cam.height = o.height;
    cam.K << f_px, 0, (o.width - 1) / 2.0 + o.principal_point_spread * o.width * jitter(i, 2),  //
        0, f_px, (o.height - 1) / 2.0 + o.principal_point_spread * o.width * jitter(i, 3),    //
        0, 0, 1;
    for (int k = 0; k < 5; ++k) cam.distortion[k] = o.distortion[k] * (1.0 + o.distortion_spread * jitter(i, 4 + k));
    cam.world_to_camera.R.row(0) = right.transpose();
    cam.world_to_camera.R.row(1) = down.transpose();
    cam.world_to_camera.R.row(2) = forward.transpose();
    cam.world_to_camera.t = -cam.world_to_camera.R * centre;
    rig.cameras.push_back(cam);
  }
  return rig;
}

}  // namespace tega::synth
