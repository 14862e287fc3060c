#include <opencv2/calib3d.hpp>

#include <Eigen/SVD>
#include <algorithm>
#include <map>
#include <queue>

#include "calibration_state.h"
#include "tega/core/error.h"

namespace tega::calibrate::detail {

namespace {

struct Edge {
  int camera, board;
  RigidTransform board_to_camera;
  int weight;  // corners seen
};

// The rotation closest (Frobenius) to the weighted mean of rotations, and the mean translation.
RigidTransform average(const std::vector<std::pair<RigidTransform, double>>& samples) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double total = 0;
  for (const auto& [transform, weight] : samples) {
    sum += weight * transform.R;
    t += weight * transform.t;
    total += weight;
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return {svd.matrixU() * d * svd.matrixV().transpose(), t / total};
}

// Corners on one line of the board (a partial view of a ChArUco board) fix
// no board pose: OpenCV's PnP and calibrateCamera fail on them.
bool spans_the_board_plane(const BoardView& view, const Board& board) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(1e9), high = -low;
  for (int id : view.ids) {
    low = low.cwiseMin(board.corners[id].head<2>());
    high = high.cwiseMax(board.corners[id].head<2>());
  }
  const double square = board.options.square_m;
  return high.x() - low.x() > 0.5 * square && high.y() - low.y() > 0.5 * square;
}

std::vector<cv::Point3f> object_points(const BoardView& view, const Board& board) {
  std::vector<cv::Point3f> points;
  for (int id : view.ids) {
    const auto& c = board.corners[id];
    points.emplace_back(float(c.x()), float(c.y()), float(c.z()));
  }
  return points;
}

std::vector<cv::Point2f> image_points(const BoardView& view) {
  std::vector<cv::Point2f> points;
  for (const auto& p : view.pixels) points.emplace_back(float(p.x()), float(p.y()));
  return points;
}

Intrinsics intrinsics_from(const cv::Mat& K, const cv::Mat& dist) {
  Intrinsics in{K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2), 0, 0, 0, 0, 0};
  for (int i = 0; i < 5 && i < int(dist.total()); ++i) in[4 + i] = dist.at<double>(i);
  return in;
}

void camera_matrices(const Intrinsics& in, cv::Mat& K, cv::Mat& dist) {
  K = (cv::Mat_<double>(3, 3) << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1);
  dist = (cv::Mat_<double>(1, 5) << in[4], in[5], in[6], in[7], in[8]);
}

RigidTransform pnp(const BoardView& view, const Board& board, const Intrinsics& in) {
  cv::Mat K, dist, rvec, tvec, R;
  camera_matrices(in, K, dist);
  cv::solvePnP(object_points(view, board), image_points(view), K, dist, rvec, tvec);
  cv::Rodrigues(rvec, R);
  RigidTransform t;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) t.R(r, c) = R.at<double>(r, c);
    t.t(r) = tvec.at<double>(r);
  }
  return t;
}

Intrinsics own_intrinsics(const std::vector<const BoardView*>& views, const Board& board, const CameraSize& size,
                          const CalibrationOptions& options) {
  if (int(views.size()) < options.min_views)
    throw Error("camera " + size.name + " sees the board in only " + std::to_string(views.size()) +
                " frame(s); its intrinsics need at least " + std::to_string(options.min_views) +
                " (film more board poses in front of it, or pass --init with a previous rig)");
  // OpenCV solves for every view's pose in one dense system, cubic in the
  // views: a sample of the richest views starts the intrinsics as well, and
  // the bundle adjustment refines them with all of them.
  constexpr size_t kViewsForIntrinsics = 20;
  std::vector<const BoardView*> sample = views;
  std::sort(sample.begin(), sample.end(), [](const auto* a, const auto* b) { return a->ids.size() > b->ids.size(); });
  sample.resize(std::min(sample.size(), kViewsForIntrinsics));
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> images;
  for (const auto* v : sample) {
    objects.push_back(object_points(*v, board));
    images.push_back(image_points(*v));
  }
  // CALIB_USE_LU for determinism: calibrateCamera's default Levenberg-Marquardt
  // step solves its ~130-unknown normal equations by SVD, which OpenCV hands to
  // LAPACK's dgesdd (>= 25 unknowns); with ATLAS (Debian's default BLAS) its
  // result depends on the alignment of OpenCV's heap scratch buffers, so the
  // same views gave intrinsics differing by ~1e-10 from run to run, and the rig
  // ~1e-14 after the bundle adjustment. The LU solve (OpenCV's own below 100
  // unknowns, LAPACK's dgesv above) gave bit-identical intrinsics across heap
  // layouts. The damped normal equations are well conditioned: same minimum.
  cv::Mat K, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::calibrateCamera(objects, images, cv::Size(size.width, size.height), K, dist, rvecs, tvecs,
                      cv::CALIB_USE_LU | (options.fix_k3 ? cv::CALIB_FIX_K3 : 0));
  return intrinsics_from(K, dist);
}

}  // namespace

Pose to_pose(const RigidTransform& transform) {
  const Eigen::AngleAxisd aa(transform.R);
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  return {r.x(), r.y(), r.z(), transform.t.x(), transform.t.y(), transform.t.z()};
}

RigidTransform to_transform(const Pose& pose) {
  const Eigen::Vector3d r(pose[0], pose[1], pose[2]);
  const double angle = r.norm();
  RigidTransform t;
  if (angle > 0) t.R = Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
  t.t = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return t;
}

CalibrationState initial_state(const std::vector<BoardView>& views, const Board& board,
                               const std::vector<CameraSize>& cameras, const CalibrationOptions& options,
                               const Rig* init) {
  const int n_cameras = int(cameras.size());
  std::vector<std::vector<const BoardView*>> by_camera(n_cameras);
  std::map<int, int> board_of_frame;  // take frame -> board pose index
  CalibrationState state;
  std::vector<const BoardView*> usable;
  for (const auto& v : views)
    if (spans_the_board_plane(v, board)) usable.push_back(&v);
  for (const auto* view : usable) {
    const auto& v = *view;
    by_camera[v.camera].push_back(&v);
    if (board_of_frame.emplace(v.frame, int(state.frames.size())).second) state.frames.push_back(v.frame);
  }

  state.intrinsics.resize(n_cameras);
  state.fixed_intrinsics.assign(n_cameras, false);
  for (int c = 0; c < n_cameras; ++c) {
    const auto& size = cameras[c];
    if (by_camera[c].empty())
      throw Error("camera " + size.name + ": the board was not found in any of its images (is the board in its view? "
                  "does the board file match the printed board?)");
    if (init && init->contains(size.name)) {
      const Camera& known = init->camera(size.name);
      if (known.width != size.width || known.height != size.height)
        throw Error("camera " + size.name + ": --init rig has it at " + std::to_string(known.width) + "x" +
                    std::to_string(known.height) + ", the take at " + std::to_string(size.width) + "x" +
                    std::to_string(size.height));
      state.intrinsics[c] = {known.K(0, 0), known.K(1, 1), known.K(0, 2), known.K(1, 2), known.distortion[0],
                             known.distortion[1], known.distortion[2], known.distortion[3], known.distortion[4]};
      state.fixed_intrinsics[c] = !options.refine_init_intrinsics;
    } else {
      state.intrinsics[c] = own_intrinsics(by_camera[c], board, size, options);
    }
  }

  std::vector<Edge> edges;
  for (int c = 0; c < n_cameras; ++c)
    for (const auto* v : by_camera[c])
      edges.push_back({c, board_of_frame.at(v->frame), pnp(*v, board, state.intrinsics[c]), int(v->ids.size())});

  const int n_boards = int(state.frames.size());
  std::vector<std::optional<RigidTransform>> world_to_camera(n_cameras), board_to_world(n_boards);
  if (options.world == "board") {
    int root = -1;
    if (options.world_board_frame >= 0) {
      const auto it = board_of_frame.find(options.world_board_frame);
      if (it == board_of_frame.end())
        throw Error("world_board_frame " + std::to_string(options.world_board_frame) + ": no camera sees the board in it");
      root = it->second;
    } else {
      std::vector<int> seen(n_boards, 0);
      for (const auto& e : edges) seen[e.board] += 1000 * 1000 + e.weight;  // most cameras, then most corners
      root = int(std::max_element(seen.begin(), seen.end()) - seen.begin());
    }
    state.fixed_board = root;
    board_to_world[root] = RigidTransform{};
  } else {
    const std::string name = options.world_camera.empty() ? cameras[0].name : options.world_camera;
    for (int c = 0; c < n_cameras; ++c)
      if (cameras[c].name == name) state.fixed_camera = c;
    if (state.fixed_camera < 0) throw Error("world_camera '" + name + "' is not a camera of the take");
    // Re-calibration keeps the previous rig's world: the world camera stays where --init has it.
    world_to_camera[state.fixed_camera] =
        init && init->contains(name) ? init->camera(name).world_to_camera : RigidTransform{};
  }

  // Prim's algorithm for the maximum spanning tree, growing from the world node.
  const auto known = [&](const Edge& e) { return world_to_camera[e.camera].has_value() + board_to_world[e.board].has_value(); };
  const auto by_weight = [&](int a, int b) { return edges[a].weight < edges[b].weight; };
  std::priority_queue<int, std::vector<int>, decltype(by_weight)> frontier(by_weight);
  const auto push_edges_of = [&](bool camera, int node) {
    for (int i = 0; i < int(edges.size()); ++i)
      if ((camera ? edges[i].camera : edges[i].board) == node && known(edges[i]) == 1) frontier.push(i);
  };
  push_edges_of(state.fixed_camera >= 0, state.fixed_camera >= 0 ? state.fixed_camera : state.fixed_board);
  while (!frontier.empty()) {
    const Edge& e = edges[frontier.top()];
    frontier.pop();
    if (known(e) != 1) continue;
    if (world_to_camera[e.camera]) {
      board_to_world[e.board] = world_to_camera[e.camera]->inverse() * e.board_to_camera;
      push_edges_of(false, e.board);
    } else {
      world_to_camera[e.camera] = e.board_to_camera * board_to_world[e.board]->inverse();
      push_edges_of(true, e.camera);
    }
  }
  for (int c = 0; c < n_cameras; ++c) {
    if (world_to_camera[c]) continue;
    std::string frames;
    for (const auto* v : by_camera[c]) frames += (frames.empty() ? "" : ", ") + std::to_string(v->frame);
    throw Error("camera " + cameras[c].name + " never shares a board view with the others: it sees the board in frames " +
                frames + ", where no camera linked to the world sees it");
  }

  // Averaging over every view refines the tree's single path to each node.
  constexpr int kAveragingRounds = 3;
  for (int round = 0; round < kAveragingRounds; ++round) {
    std::vector<std::vector<std::pair<RigidTransform, double>>> camera_samples(n_cameras), board_samples(n_boards);
    for (const auto& e : edges) {
      camera_samples[e.camera].push_back({e.board_to_camera * board_to_world[e.board]->inverse(), e.weight});
      board_samples[e.board].push_back({world_to_camera[e.camera]->inverse() * e.board_to_camera, e.weight});
    }
    for (int c = 0; c < n_cameras; ++c)
      if (c != state.fixed_camera) world_to_camera[c] = average(camera_samples[c]);
    for (int b = 0; b < n_boards; ++b)
      if (b != state.fixed_board) board_to_world[b] = average(board_samples[b]);
  }

  for (const auto& t : world_to_camera) state.world_to_camera.push_back(to_pose(*t));
  for (const auto& t : board_to_world) state.board_to_world.push_back(to_pose(*t));
  for (const auto* v : usable)
    for (size_t i = 0; i < v->ids.size(); ++i)
      state.observations.push_back({v->camera, board_of_frame.at(v->frame), v->ids[i], v->pixels[i], false});
  return state;
}

}  // namespace tega::calibrate::detail
