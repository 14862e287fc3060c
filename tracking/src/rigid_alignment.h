#pragma once
// The rigid motion that best maps one point set onto another.

#include <Eigen/Core>
#include <vector>

#include "tega/core/geometry.h"

namespace tega::tracking {

// The rotation and translation taking `from` onto `to` in the least-squares
// sense (Kabsch; no scale). The sets pair up by index.
RigidTransform align(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

}  // namespace tega::tracking
