#pragma once
// Questions to a scanned surface (a frame's multi-view stereo mesh), asked
// in batches: the closest surface point to each query point (core's exact
// triangle tree; Debian's Open3D 0.16 aborts on an assertion in its
// closest-point query for some Poisson meshes), and whether the straight
// line from a camera to a point is blocked (Open3D's ray casting, Embree).

#include <Eigen/Core>
#include <memory>
#include <mutex>
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
  ~SurfaceQuery();
  SurfaceQuery(const SurfaceQuery&) = delete;
  SurfaceQuery& operator=(const SurfaceQuery&) = delete;

  std::vector<ClosestPoint> closest(const std::vector<Eigen::Vector3d>& points) const;
  // For each point: does the surface cross the segment from `eye` to the
  // point before `margin_m` short of it?
  std::vector<bool> occluded(const Eigen::Vector3d& eye, const std::vector<Eigen::Vector3d>& points,
                             double margin_m) const;

 private:
  struct Scene;
  Scene& scene() const;

  Mesh surface_;
  TriangleDistanceTree tree_;
  Vertices face_normals_;
  mutable std::once_flag scene_built_;
  mutable std::unique_ptr<Scene> scene_;
};

}  // namespace tega::tracking
