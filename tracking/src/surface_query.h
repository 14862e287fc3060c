#pragma once
// Questions to a surface (a frame's multi-view stereo mesh, the model's
// lids), asked in batches and answered by core's triangle tree: the closest
// surface point to each query point, and whether the straight line from a
// camera to a point is blocked. Debian's Open3D 0.16 serves neither: its
// closest-point query aborts on an assertion for some Poisson meshes, and
// its ray casting finds no hit at all (not even a ray through a single
// triangle: tests/tracking/surface_query_test.cpp).

#include <Eigen/Core>
#include <vector>

#include "tega/core/mesh.h"
#include "tega/core/triangle_distance_tree.h"

namespace tega::tracking {

struct ClosestPoint {
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  // unit normal of the triangle it lies on
};

class SurfaceQuery {
 public:
  explicit SurfaceQuery(const Mesh& surface);

  std::vector<ClosestPoint> closest(const std::vector<Eigen::Vector3d>& points) const;
  // For each point: does the surface cross the segment from `eye` to the
  // point before `margin_m` short of it?
  std::vector<bool> occluded(const Eigen::Vector3d& eye, const std::vector<Eigen::Vector3d>& points,
                             double margin_m) const;

 private:
  TriangleDistanceTree tree_;
  Vertices face_normals_;
};

}  // namespace tega::tracking
