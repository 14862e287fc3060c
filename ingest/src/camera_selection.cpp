#include "tega/ingest/camera_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tega/core/error.h"

namespace tega::ingest {
namespace {

constexpr double kDegrees = 180.0 / M_PI;

Eigen::Vector3d unit(const Eigen::Vector3d& v, const std::string& what) {
  if (v.norm() < 1e-6) throw Error("cannot tell the " + what + " of the head from the rig; set the cameras explicitly");
  return v.normalized();
}

Eigen::Vector3d direction_at(const HeadFrame& head, double azimuth_deg) {
  const double a = azimuth_deg / kDegrees;
  return std::cos(a) * head.forward + std::sin(a) * head.left;
}

}  // namespace

HeadFrame estimate_head_frame(const Rig& rig, const std::vector<RigidTransform>& head_poses,
                              const std::vector<double>& face_forward_head) {
  HeadFrame head;
  head.centre = Eigen::Vector3d::Zero();
  for (const auto& pose : head_poses) head.centre += pose.t;
  head.centre /= static_cast<double>(head_poses.size());

  Eigen::Vector3d up = Eigen::Vector3d::Zero(), towards_cameras = Eigen::Vector3d::Zero();
  for (const Camera& camera : rig.cameras) {
    // The camera's -y axis in the world: the up of its image.
    up -= camera.world_to_camera.R.row(1).transpose();
    towards_cameras += (camera.center() - head.centre).normalized();
  }
  head.up = unit(up, "up direction");

  Eigen::Vector3d forward = Eigen::Vector3d::Zero();
  if (face_forward_head.empty()) {
    forward = towards_cameras;
  } else {
    if (face_forward_head.size() != 3) throw Error("face_forward: expected 3 numbers (a head-space direction)");
    const Eigen::Vector3d axis(face_forward_head[0], face_forward_head[1], face_forward_head[2]);
    for (const auto& pose : head_poses) forward += pose.R * axis;
  }
  head.forward = unit(forward - forward.dot(head.up) * head.up, "forward direction");
  head.left = head.up.cross(head.forward);
  return head;
}

CameraPlacement placement_of(const Camera& camera, const HeadFrame& head) {
  const Eigen::Vector3d d = (camera.center() - head.centre).normalized();
  return {std::atan2(d.dot(head.left), d.dot(head.forward)) * kDegrees,
          std::asin(std::clamp(d.dot(head.up), -1.0, 1.0)) * kDegrees};
}

CameraSplit select_cameras(const Rig& rig, const HeadFrame& head, const IngestOptions& options,
                           const std::filesystem::path& krt) {
  for (const auto* names : {&options.cameras, &options.test_cameras}) {
    for (const auto& name : *names)
      if (!rig.contains(name)) throw Error(krt, "has no camera '" + name + "' (named in the ingest options)");
  }
  std::vector<std::string> kept;
  for (const Camera& camera : rig.cameras) {
    const CameraPlacement p = placement_of(camera, head);
    const bool listed = std::count(options.cameras.begin(), options.cameras.end(), camera.name) > 0;
    const bool in_front = std::abs(p.azimuth_deg) <= options.max_azimuth_deg && p.elevation_deg <= options.max_elevation_deg;
    if (options.cameras.empty() ? in_front : listed) kept.push_back(camera.name);
  }

  std::vector<std::string> held_out = options.test_cameras;
  if (held_out.empty()) {
    for (double azimuth : options.test_camera_azimuths_deg) {
      const Eigen::Vector3d target = direction_at(head, azimuth);
      std::string best;
      double best_cos = -std::numeric_limits<double>::infinity();
      for (const auto& name : kept) {
        if (std::count(held_out.begin(), held_out.end(), name)) continue;
        const double c = (rig.camera(name).center() - head.centre).normalized().dot(target);
        if (c > best_cos) best_cos = c, best = name;
      }
      if (!best.empty()) held_out.push_back(best);
    }
  }

  CameraSplit split;
  split.test = held_out;
  for (const auto& name : kept)
    if (!std::count(held_out.begin(), held_out.end(), name)) split.train.push_back(name);
  if (split.train.empty())
    throw Error(krt, "no training camera remains after the camera selection and the held-out cameras");
  return split;
}

}  // namespace tega::ingest
