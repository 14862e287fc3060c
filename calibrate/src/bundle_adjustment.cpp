#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <ceres/rotation.h>

#include "calibration_state.h"
#include "tega/core/thread_pool.h"

namespace tega::calibrate::detail {

namespace {

// A board corner seen by a camera: board -> world -> camera -> OpenCV lens -> pixel.
struct CornerReprojection {
  Eigen::Vector3d corner;
  Eigen::Vector2d pixel;

  template <typename T>
  bool operator()(const T* intrinsics, const T* world_to_camera, const T* board_to_world, T* residual) const {
    const T corner_board[3] = {T(corner.x()), T(corner.y()), T(corner.z())};
    T world[3], camera[3];
    ceres::AngleAxisRotatePoint(board_to_world, corner_board, world);
    for (int i = 0; i < 3; ++i) world[i] += board_to_world[3 + i];
    ceres::AngleAxisRotatePoint(world_to_camera, world, camera);
    for (int i = 0; i < 3; ++i) camera[i] += world_to_camera[3 + i];
    const T x = camera[0] / camera[2], y = camera[1] / camera[2];
    const T& k1 = intrinsics[4];
    const T& k2 = intrinsics[5];
    const T& p1 = intrinsics[6];
    const T& p2 = intrinsics[7];
    const T& k3 = intrinsics[8];
    const T r2 = x * x + y * y;
    const T radial = T(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
    const T xd = x * radial + T(2) * p1 * x * y + p2 * (r2 + T(2) * x * x);
    const T yd = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * x * y;
    residual[0] = intrinsics[0] * xd + intrinsics[2] - T(pixel.x());
    residual[1] = intrinsics[1] * yd + intrinsics[3] - T(pixel.y());
    return true;
  }
};

}  // namespace

Eigen::Vector2d residual(const CalibrationState& state, const Board& board, const Observation& o) {
  const CornerReprojection f{board.corners[o.id], o.pixel};
  double r[2];
  f(state.intrinsics[o.camera].data(), state.world_to_camera[o.camera].data(), state.board_to_world[o.board].data(), r);
  return {r[0], r[1]};
}

void bundle_adjust(CalibrationState& state, const Board& board, const CalibrationOptions& options) {
  ceres::Problem problem;
  for (const auto& o : state.observations) {
    if (o.outlier) continue;
    auto* cost = new ceres::AutoDiffCostFunction<CornerReprojection, 2, 9, 6, 6>(
        new CornerReprojection{board.corners[o.id], o.pixel});
    problem.AddResidualBlock(cost, new ceres::HuberLoss(options.robust_loss_px), state.intrinsics[o.camera].data(),
                             state.world_to_camera[o.camera].data(), state.board_to_world[o.board].data());
  }
  for (size_t c = 0; c < state.intrinsics.size(); ++c) {
    double* intrinsics = state.intrinsics[c].data();
    if (!problem.HasParameterBlock(intrinsics)) continue;
    if (state.fixed_intrinsics[c]) {
      problem.SetParameterBlockConstant(intrinsics);
    } else if (options.fix_k3) {
      problem.SetManifold(intrinsics, new ceres::SubsetManifold(9, {8}));
    }
  }
  if (state.fixed_camera >= 0) problem.SetParameterBlockConstant(state.world_to_camera[state.fixed_camera].data());
  if (state.fixed_board >= 0 && problem.HasParameterBlock(state.board_to_world[state.fixed_board].data()))
    problem.SetParameterBlockConstant(state.board_to_world[state.fixed_board].data());

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;  // board poses are eliminated first
  solver.max_num_iterations = 200;
  solver.function_tolerance = 1e-10;
  solver.parameter_tolerance = 1e-10;
  solver.num_threads = options.threads > 0 ? options.threads : default_thread_count();
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
}

}  // namespace tega::calibrate::detail
