#include "tega/mvs/view_selection.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace tega::mvs {
namespace {

constexpr double kDegree = M_PI / 180.0;

Eigen::Vector3d optical_axis(const Camera& c) { return c.world_to_camera.R.row(2).transpose(); }

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

std::vector<int> best_ranked(std::vector<std::pair<double, int>> scored, int count) {
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> chosen;
  for (const auto& [score, index] : scored)
    if (score > 0 && static_cast<int>(chosen.size()) < count) chosen.push_back(index);
  return chosen;
}

}  // namespace

std::optional<Eigen::Vector3d> rig_focus_point(const std::vector<Camera>& cameras) {
  // Sum over axes of (I - a a^T)(x - c) = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& c : cameras) {
    const Eigen::Vector3d a = optical_axis(c);
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - a * a.transpose();
    A += P;
    b += P * c.center();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
  if (cameras.size() < 2 || eigen.eigenvalues()(0) < 1e-3 * eigen.eigenvalues()(2)) return std::nullopt;
  const Eigen::Vector3d focus = A.ldlt().solve(b);
  int in_front = 0;
  for (const auto& c : cameras) in_front += c.world_to_camera.apply(focus).z() > 0;
  if (2 * in_front <= static_cast<int>(cameras.size())) return std::nullopt;
  return focus;
}

std::vector<std::vector<int>> select_source_views(const std::vector<Camera>& cameras, const Eigen::Vector3d& subject,
                                                  int count) {
  std::vector<std::vector<int>> sources(cameras.size());
  for (size_t r = 0; r < cameras.size(); ++r) {
    const Eigen::Vector3d to_r = cameras[r].center() - subject;
    std::vector<std::pair<double, int>> scored;
    for (size_t s = 0; s < cameras.size(); ++s) {
      if (s == r) continue;
      const double angle = angle_between(to_r, cameras[s].center() - subject);
      if (angle < 2 * kDegree || angle > 60 * kDegree) continue;
      // Wide enough to triangulate well, narrow enough to keep the windows alike.
      const double offset = (angle - 15 * kDegree) / (angle < 15 * kDegree ? 8 * kDegree : 20 * kDegree);
      const double facing = std::max(0.0, optical_axis(cameras[r]).dot(optical_axis(cameras[s])));
      scored.push_back({std::exp(-0.5 * offset * offset) * (0.5 + 0.5 * facing), int(s)});
    }
    sources[r] = best_ranked(std::move(scored), count);
  }
  return sources;
}

std::vector<std::vector<int>> select_source_views_by_axes(const std::vector<Camera>& cameras, int count) {
  std::vector<std::vector<int>> sources(cameras.size());
  for (size_t r = 0; r < cameras.size(); ++r) {
    std::vector<std::pair<double, int>> scored;
    for (size_t s = 0; s < cameras.size(); ++s) {
      if (s == r) continue;
      const double angle = angle_between(optical_axis(cameras[r]), optical_axis(cameras[s]));
      if (angle < 60 * kDegree && cameras[s].center() != cameras[r].center())
        scored.push_back({std::cos(angle), int(s)});
    }
    sources[r] = best_ranked(std::move(scored), count);
  }
  return sources;
}

}  // namespace tega::mvs
