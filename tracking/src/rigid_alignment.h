#pragma once
// Rigid motions of point sets: the one that best maps a set onto another,
// and moving a mesh's vertices by one.

#include <Eigen/Core>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega::tracking {

// The rotation and translation taking `from` onto `to` in the least-squares
// sense (Kabsch; no scale). The sets pair up by index.
RigidTransform align(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

// Every vertex moved by `pose` (head space to world space, say).
Vertices posed(const Vertices& head, const RigidTransform& pose);

}  // namespace tega::tracking
