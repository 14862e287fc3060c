#pragma once
// What the calibration estimates, in the layout the bundle adjustment
// optimises: angle-axis rotations, OpenCV intrinsics.
#include <array>
#include <vector>

#include "tega/calibrate/calibration.h"

namespace tega::calibrate::detail {

// fx, fy, cx, cy, k1, k2, p1, p2, k3
using Intrinsics = std::array<double, 9>;
// angle-axis (3), translation (3)
using Pose = std::array<double, 6>;

Pose to_pose(const RigidTransform& transform);
RigidTransform to_transform(const Pose& pose);

struct Observation {
  int camera = 0, board = 0;  // board: index into CalibrationState::frames
  int id = 0;                 // corner id
  Eigen::Vector2d pixel;
  bool outlier = false;
};

struct CalibrationState {
  std::vector<Intrinsics> intrinsics;    // per camera
  std::vector<Pose> world_to_camera;     // per camera
  std::vector<int> frames;               // the take frame of each board pose
  std::vector<Pose> board_to_world;      // per board pose
  std::vector<Observation> observations;
  int fixed_camera = -1;  // world = camera: its pose is the identity and stays fixed
  int fixed_board = -1;   // world = board: that board pose is the identity and stays fixed
  std::vector<bool> fixed_intrinsics;  // per camera: kept as --init has them
};

// Per-camera intrinsics (OpenCV calibrateCamera, or `init`'s) and per-view
// board poses, then a maximum spanning tree over cameras and board poses
// (edges weighted by shared corners) from the world node, then rounds of
// averaging every camera over its board views and every board over its cameras.
CalibrationState initial_state(const std::vector<BoardView>& views, const Board& board,
                               const std::vector<CameraSize>& cameras, const CalibrationOptions& options,
                               const Rig* init);

// Ceres: every intrinsic, camera pose and board pose but the world's; Huber
// loss; observations marked outlier are left out.
void bundle_adjust(CalibrationState& state, const Board& board, const CalibrationOptions& options);

// Reprojection minus detection of observation `o` with the current state, in pixels.
Eigen::Vector2d residual(const CalibrationState& state, const Board& board, const Observation& o);

}  // namespace tega::calibrate::detail
