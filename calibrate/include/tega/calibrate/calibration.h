#pragma once
// Multi-camera calibration from board views (docs/calibration.md): per-camera
// intrinsics, a pose graph over cameras and board poses for the starting
// extrinsics, then one bundle adjustment (Ceres) over every intrinsic,
// extrinsic and board pose with a robust loss and outlier rejection.
#include <optional>
#include <string>
#include <vector>

#include "tega/calibrate/board.h"
#include "tega/calibrate/detection.h"
#include "tega/core/rig.h"

namespace tega::calibrate {

struct CalibrationOptions {
  std::string world = "camera";  // camera | board
  std::string world_camera;      // world = camera: its name; "" = the take's first camera
  int world_board_frame = -1;    // world = board: the frame whose board pose is the world; -1 = the best-seen frame
  double robust_loss_px = 1.0;
  double outlier_px = 2.0;
  bool fix_k3 = true;
  bool refine_init_intrinsics = false;
  int min_views = 4;             // board views a camera needs for its intrinsics (without --init)
  double min_coverage = 0.5;     // warn below this fraction of the image covered by corners
  int threads = 0;
  template <class V>
  void visit(V& v) {
    v("world", world, "What the world frame is: camera (a camera's frame) or board (the board at one frame).");
    v("world_camera", world_camera, "world: camera: the camera whose frame is the world; empty = the first camera.");
    v("world_board_frame", world_board_frame,
      "world: board: the frame whose board pose is the world; -1 = the frame most cameras see.");
    v("robust_loss_px", robust_loss_px, "Huber loss scale in pixels: residuals beyond it count linearly.");
    v("outlier_px", outlier_px,
      "After the first solve, corners further than this from their reprojection are removed and the problem "
      "solved again.");
    v("fix_k3", fix_k3,
      "Keep the sixth-order radial term k3 at 0 (or at --init's value): it matters only for wide-angle lenses; "
      "free on a studio lens it trades off against k1, k2 and the principal point.");
    v("refine_init_intrinsics", refine_init_intrinsics,
      "With --init: solve for the intrinsics too (needs as many board poses as a first calibration); by default "
      "they stay as --init has them and only the poses are solved, which a few board poses suffice for.");
    v("min_views", min_views, "Board views a camera needs to estimate its own intrinsics (without --init).");
    v("min_coverage", min_coverage, "Warn when a camera's corners cover less of its image than this (0-1).");
    v("threads", threads, "Threads for detection and the solver; 0 = one per hardware thread.");
  }
};

struct CameraSize {
  std::string name;
  int width = 0, height = 0;
};

struct Residual {
  Eigen::Vector2d pixel;     // detected corner
  Eigen::Vector2d residual;  // reprojection - detection, pixels
  bool outlier = false;
};

struct CameraReport {
  std::string name;
  int views = 0, corners = 0, outliers = 0;
  double rms_px = 0;
  double coverage = 0;  // fraction of a 10 x 10 grid over the image holding a corner
  std::optional<double> moved_mm, rotated_deg;  // against --init
  std::vector<Residual> residuals;
};

struct Calibration {
  Rig rig;
  std::vector<CameraReport> cameras;
  std::vector<std::pair<int, RigidTransform>> board_to_world;  // per frame used
  double rms_px = 0;
  int outliers = 0;
  std::string world;  // "camera cam00" or "board at frame 12"
  double seconds = 0;
};

// With `init`, its intrinsics start the solve and, for world = camera, the
// world camera keeps its `init` pose: the rig stays in `init`'s world.
// Throws tega::Error naming the camera when a camera sees no board, too few
// views for its intrinsics, or never shares a view with the others.
Calibration calibrate_rig(const std::vector<BoardView>& views, const Board& board,
                          const std::vector<CameraSize>& cameras, const CalibrationOptions& options,
                          const Rig* init = nullptr);

}  // namespace tega::calibrate
