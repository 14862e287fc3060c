#pragma once
// An oriented, coloured point cloud: what depth-map fusion produces and what
// surface reconstruction consumes (COLMAP's fused.ply holds the same).

#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::mvs {

using Colors = Eigen::Matrix<uint8_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct OrientedPointCloud {
  Vertices points;   // N x 3, metres, world space
  Vertices normals;  // N x 3, unit length, pointing out of the surface (towards the cameras that saw it)
  Colors colors;     // N x 3 RGB, or empty
  int size() const { return static_cast<int>(points.rows()); }
};

}  // namespace tega::mvs
