#include "tega/scoring/tracking_scores.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/json_file.h"
#include "tega/core/mesh.h"
#include "tega/core/progress.h"
#include "tega/core/tracked.h"
#include "tega/scoring/studio_truth.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

Eigen::Matrix3d rotation_of(const nlohmann::json& rows) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = rows.at(r).at(c);
  return R;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = double(a.size());
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

}  // namespace

TakeTruth::TakeTruth(const fs::path& capture, const std::string& take)
    : frames_file_(capture / "ground_truth" / take / "frames.json"),
      take_(take),
      studio_(std::make_unique<StudioTruthSource>(capture)),
      model_vertex_(studio_model_vertices(capture)) {
  neutral_ = read_obj(capture / "ground_truth" / "head" / "template.obj").positions;
  const int coarse_vertices = int(neutral_.rows());
  const nlohmann::json frames = read_json_file(frames_file_);
  for (const auto& f : frames.at("frames")) {
    const int frame = f.at("index").get<int>();
    rotation_[frame] = rotation_of(f.at("head_to_world"));
    for (const auto& [expression, value] : f.at("expression").items()) expression_[frame][expression] = value.get<double>();
    char name[32];
    std::snprintf(name, sizeof name, "%06d.bin", frame);
    coarse_[frame] = read_vertices_bin(capture / "ground_truth" / take / "coarse" / name, coarse_vertices);
  }
  if (rotation_.empty()) throw Error(frames_file_, "lists no frame");
}

TakeTruth::~TakeTruth() = default;

const std::vector<int>& TakeTruth::face_vertices(int frame) const {
  auto found = face_vertices_.find(frame);
  if (found == face_vertices_.end())
    found = face_vertices_.emplace(frame, studio_->frame(take_, frame).face_vertices).first;
  return found->second;
}

TrackScores TakeTruth::score(const std::vector<ScoredFrame>& tracked, const Vertices* subject_neutral) const {
  TrackScores scores;
  // The fitted neutral ~ subject_turn * true neutral + a shift, in head space.
  Eigen::Matrix3d subject_turn = Eigen::Matrix3d::Identity();
  if (subject_neutral) {
    const std::vector<int>& face = face_vertices(rotation_.begin()->first);
    Eigen::Matrix3Xd truth_points(3, face.size()), fitted_points(3, face.size());
    for (size_t i = 0; i < face.size(); ++i) {
      const int v = face[i], m = model_vertex_[size_t(v)];
      if (m >= subject_neutral->rows()) throw Error("the subject's neutral has fewer vertices than the studio's face region needs");
      truth_points.col(Eigen::Index(i)) = neutral_.row(v).cast<double>().transpose();
      fitted_points.col(Eigen::Index(i)) = subject_neutral->row(m).cast<double>().transpose();
    }
    subject_turn = Eigen::umeyama(truth_points, fitted_points, false).topLeftCorner<3, 3>();
    scores.subject_rotation_deg = Eigen::AngleAxisd(subject_turn).angle() * 180 / M_PI;
  }
  std::vector<double> errors, rotations, pose_rotations;
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> series;  // truth, tracked
  // A frame's face region renders its fine head from every camera: seconds a frame at the studio's size.
  Progress progress("scoring tracked take " + take_ + " against the studio's truth", int64_t(tracked.size()), "frames");
  for (const ScoredFrame& t : tracked) {
    if (!rotation_.count(t.frame)) throw Error(frames_file_, "has no frame " + std::to_string(t.frame));
    const Vertices& true_mesh = coarse_.at(t.frame);
    for (int v : face_vertices(t.frame)) {
      const int m = model_vertex_[size_t(v)];
      if (m >= t.vertices.rows()) throw Error("a tracked mesh has fewer vertices than the studio's face region needs");
      errors.push_back((t.vertices.row(m) - true_mesh.row(v)).cast<double>().norm());
    }
    const Eigen::Matrix3d& R_true = rotation_.at(t.frame);
    rotations.push_back(Eigen::AngleAxisd((t.head_rotation * subject_turn).transpose() * R_true).angle() * 180 / M_PI);
    pose_rotations.push_back(Eigen::AngleAxisd(t.head_rotation.transpose() * R_true).angle() * 180 / M_PI);
    for (const auto& [expression, value] : expression_.at(t.frame)) {
      auto& [truth_values, tracked_values] = series[expression];
      truth_values.push_back(value);
      tracked_values.push_back(t.expression.count(expression) ? t.expression.at(expression) : 0.0);
    }
    ++scores.frames;
    progress.advance();
  }
  progress.finish();
  if (scores.frames == 0) throw Error("no tracked frame to score");
  scores.vertex_median_m = percentile(errors, 0.5);
  scores.vertex_p95_m = percentile(errors, 0.95);
  scores.rotation_median_deg = percentile(rotations, 0.5);
  scores.rotation_max_deg = *std::max_element(rotations.begin(), rotations.end());
  if (subject_neutral) scores.pose_rotation_median_deg = percentile(pose_rotations, 0.5);
  for (const auto& [expression, values] : series) {
    const auto& truth_values = values.first;
    if (*std::max_element(truth_values.begin(), truth_values.end()) - *std::min_element(truth_values.begin(), truth_values.end()) > 0.1)
      scores.correlation[expression] = pearson(truth_values, values.second);
  }
  return scores;
}

TrackScores score_against_studio(const fs::path& tracked, const fs::path& capture, const std::string& take,
                                 const RigidTransform& tracked_to_truth) {
  return score_against_studio(tracked, TakeTruth(capture, take), tracked_to_truth);
}

TrackScores score_against_studio(const fs::path& tracked, const TakeTruth& truth,
                                 const RigidTransform& tracked_to_truth) {
  const std::string& take = truth.take();
  std::vector<ScoredFrame> scored;
  for (const TrackedFrame& frame : read_tracked_take(tracked, take)) {
    if (!frame.tracked()) continue;
    Vertices vertices = transformed(tracked_to_truth, read_vertices_bin(frame.mesh));
    scored.push_back({frame.frame, std::move(vertices), tracked_to_truth.R * frame.head_to_world.R, frame.expression});
  }
  if (scored.empty()) throw Error(tracked / take, "has no tracked frame to score");
  const fs::path neutral_file = tracked / "identity_neutral.obj";
  if (!fs::exists(neutral_file)) return truth.score(scored);
  const Vertices neutral = read_obj(neutral_file).positions;
  return truth.score(scored, &neutral);
}

bool has_correlation_target(const std::string& expression) {
  return expression.rfind("eyeBlink", 0) == 0 || expression.rfind("jaw", 0) == 0;
}

}  // namespace tega::scoring
