#include "rigid_alignment.h"

#include <Eigen/SVD>

namespace tega::tracking {

RigidTransform align(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) mean_from += from[i], mean_to += to[i];
  mean_from /= double(from.size());
  mean_to /= double(to.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) covariance += (to[i] - mean_to) * (from[i] - mean_from).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) d(2, 2) = -1;
  RigidTransform pose;
  pose.R = svd.matrixU() * d * svd.matrixV().transpose();
  pose.t = mean_to - pose.R * mean_from;
  return pose;
}

Vertices posed(const Vertices& head, const RigidTransform& pose) {
  Vertices world(head.rows(), 3);
  const Eigen::Matrix3f R = pose.R.cast<float>();
  const Eigen::RowVector3f t = pose.t.cast<float>().transpose();
  for (Eigen::Index v = 0; v < head.rows(); ++v) world.row(v) = head.row(v) * R.transpose() + t;
  return world;
}

}  // namespace tega::tracking
