#pragma once
// Which cameras of a capture the dataset uses, and which it holds out
// (docs/multiface.md#cameras). Cameras are placed relative to the head:
// azimuth around the up axis from the face's forward direction, elevation
// above the head's horizontal plane.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/rig.h"
#include "tega/ingest/options.h"

namespace tega::ingest {

// World-space directions of the head, averaged over the frames.
struct HeadFrame {
  Eigen::Vector3d centre;   // mean head position
  Eigen::Vector3d forward;  // horizontal: out of the face
  Eigen::Vector3d up;
  Eigen::Vector3d left;     // up x forward: the subject's left
};

// up: the mean image-up direction of the cameras (studio images are upright).
// forward: `face_forward_head` (head space) carried by the head poses, or,
// when empty, the mean direction from the head to the cameras (a studio rig
// surrounds the face, not the back of the head); either made horizontal.
// Throws tega::Error when a direction is undefined (opposite cameras cancel).
HeadFrame estimate_head_frame(const Rig& rig, const std::vector<RigidTransform>& head_poses,
                              const std::vector<double>& face_forward_head);

struct CameraPlacement {
  double azimuth_deg = 0;    // positive towards the subject's left
  double elevation_deg = 0;  // positive above the head
};
CameraPlacement placement_of(const Camera& camera, const HeadFrame& head);

struct CameraSplit {
  std::vector<std::string> train;  // rig order
  std::vector<std::string> test;   // in the order they were named or targeted
};

// Kept: options.cameras, or the cameras within max_azimuth_deg and
// max_elevation_deg. Held out (test): options.test_cameras, or per
// test_camera_azimuths_deg the kept camera nearest to that azimuth at eye
// level. Train: the kept cameras not held out. Throws tega::Error naming `krt` for an unknown camera
// name or when no training camera remains.
CameraSplit select_cameras(const Rig& rig, const HeadFrame& head, const IngestOptions& options,
                           const std::filesystem::path& krt);

}  // namespace tega::ingest
