#pragma once
// Small geometric types shared by all stages. Units: metres; right-handed.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tega {

// x' = R x + t. Used for world-to-camera extrinsics and for head poses
// (head/mesh space to world).
struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return R * x + t; }
  RigidTransform inverse() const { return {R.transpose(), -R.transpose() * t}; }
  RigidTransform operator*(const RigidTransform& o) const { return {R * o.R, R * o.t + t}; }
  Eigen::Matrix<double, 3, 4> matrix() const {
    Eigen::Matrix<double, 3, 4> m;
    m << R, t;
    return m;
  }
  static RigidTransform from_matrix(const Eigen::Matrix<double, 3, 4>& m) {
    return {m.leftCols<3>(), m.col(3)};
  }
};

}  // namespace tega
