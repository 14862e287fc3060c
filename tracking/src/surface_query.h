#pragma once
// Questions to a scanned surface (a frame's multi-view stereo mesh), asked
// in batches through Open3D's ray-casting scene (Embree): the closest
// surface point to each query point, and whether the straight line from a
// camera to a point is blocked.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "tega/core/mesh.h"

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
  std::unique_ptr<Scene> scene_;
};

}  // namespace tega::tracking
