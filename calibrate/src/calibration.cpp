#include "tega/calibrate/calibration.h"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <set>

#include "calibration_state.h"
#include "tega/core/log.h"

namespace tega::calibrate {

namespace {

constexpr int kCoverageGrid = 10;

Camera camera_of(const detail::CalibrationState& state, int c, const CameraSize& size) {
  const auto& in = state.intrinsics[c];
  Camera camera;
  camera.name = size.name;
  camera.width = size.width;
  camera.height = size.height;
  camera.K << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1;
  camera.distortion = {in[4], in[5], in[6], in[7], in[8]};
  camera.world_to_camera = detail::to_transform(state.world_to_camera[c]);
  return camera;
}

// Residuals, coverage and RMS of every camera with the current state.
std::vector<CameraReport> camera_reports(const detail::CalibrationState& state, const Board& board,
                                         const std::vector<CameraSize>& cameras) {
  std::vector<CameraReport> reports(cameras.size());
  std::vector<std::vector<bool>> covered(cameras.size(), std::vector<bool>(kCoverageGrid * kCoverageGrid, false));
  std::vector<std::set<int>> views(cameras.size());
  for (const auto& o : state.observations) {
    auto& r = reports[o.camera];
    r.residuals.push_back({o.pixel, detail::residual(state, board, o), o.outlier});
    views[o.camera].insert(o.board);
    if (o.outlier) {
      ++r.outliers;
      continue;
    }
    ++r.corners;
    r.rms_px += r.residuals.back().residual.squaredNorm();
    const auto& size = cameras[o.camera];
    const int gx = std::clamp(int(o.pixel.x() / size.width * kCoverageGrid), 0, kCoverageGrid - 1);
    const int gy = std::clamp(int(o.pixel.y() / size.height * kCoverageGrid), 0, kCoverageGrid - 1);
    covered[o.camera][gy * kCoverageGrid + gx] = true;
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    auto& r = reports[c];
    r.name = cameras[c].name;
    r.views = int(views[c].size());
    r.rms_px = r.corners > 0 ? std::sqrt(r.rms_px / r.corners) : 0;
    r.coverage = double(std::count(covered[c].begin(), covered[c].end(), true)) / covered[c].size();
  }
  return reports;
}

}  // namespace

Calibration calibrate_rig(const std::vector<BoardView>& views, const Board& board,
                          const std::vector<CameraSize>& cameras, const CalibrationOptions& options, const Rig* init) {
  const auto start = std::chrono::steady_clock::now();
  const auto since = [&start] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  detail::CalibrationState state = detail::initial_state(views, board, cameras, options, init);
  logging::info("calibration: intrinsics and pose graph in %.1f s", since());
  detail::bundle_adjust(state, board, options);
  logging::info("calibration: bundle adjustment in %.1f s", since());
  // Misdetections (a corner interpolated across a glare, a flipped marker) sit
  // pixels away once everything else fits: drop them and solve again.
  int outliers = 0;
  for (auto& o : state.observations) {
    o.outlier = detail::residual(state, board, o).norm() > options.outlier_px;
    outliers += o.outlier;
  }
  if (outliers > 0) detail::bundle_adjust(state, board, options);

  Calibration result;
  result.cameras = camera_reports(state, board, cameras);
  result.outliers = outliers;
  double squared = 0;
  int corners = 0;
  for (size_t c = 0; c < cameras.size(); ++c) {
    result.rig.cameras.push_back(camera_of(state, int(c), cameras[c]));
    auto& report = result.cameras[c];
    squared += report.rms_px * report.rms_px * report.corners;
    corners += report.corners;
    if (init && init->contains(cameras[c].name)) {
      const Camera& before = init->camera(cameras[c].name);
      const Camera& after = result.rig.cameras.back();
      report.moved_mm = (after.center() - before.center()).norm() * 1000;
      const Eigen::AngleAxisd turn(after.world_to_camera.R * before.world_to_camera.R.transpose());
      report.rotated_deg = turn.angle() * 180 / M_PI;
    }
    if (report.coverage < options.min_coverage)
      logging::warn("camera %s: the board's corners cover only %.0f%% of its image; move the board into its corners "
                    "for reliable distortion",
                    cameras[c].name.c_str(), 100 * report.coverage);
  }
  result.rms_px = corners > 0 ? std::sqrt(squared / corners) : 0;
  result.rig.validate("calibration");
  for (size_t b = 0; b < state.frames.size(); ++b)
    result.board_to_world.emplace_back(state.frames[b], detail::to_transform(state.board_to_world[b]));
  result.world = state.fixed_camera >= 0 ? "camera " + cameras[state.fixed_camera].name
                                         : "board at frame " + std::to_string(state.frames[state.fixed_board]);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace tega::calibrate
