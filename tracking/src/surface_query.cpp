#include "surface_query.h"

#include <Eigen/Geometry>

#include "tega/core/thread_pool.h"

namespace tega::tracking {

SurfaceQuery::SurfaceQuery(const Mesh& surface) : tree_(surface), face_normals_(surface.num_faces(), 3) {
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Eigen::Vector3f a = surface.positions.row(surface.faces(f, 0)), b = surface.positions.row(surface.faces(f, 1)),
                          c = surface.positions.row(surface.faces(f, 2));
    face_normals_.row(f) = (b - a).cross(c - a).normalized().transpose();
  }
}

std::vector<ClosestPoint> SurfaceQuery::closest(const std::vector<Eigen::Vector3d>& points) const {
  std::vector<ClosestPoint> out(points.size());
  ThreadPool pool(0);
  pool.parallel_for(0, int64_t(points.size()), [&](int64_t i) {
    const auto found = tree_.closest(points[size_t(i)]);
    out[size_t(i)].point = found.point;
    out[size_t(i)].normal = face_normals_.row(std::max(0, found.face)).cast<double>().transpose();
  });
  return out;
}

std::vector<bool> SurfaceQuery::occluded(const Eigen::Vector3d& eye, const std::vector<Eigen::Vector3d>& points,
                                         double margin_m) const {
  std::vector<char> blocked(points.size(), 0);
  ThreadPool pool(0);
  pool.parallel_for(0, int64_t(points.size()), [&](int64_t i) {
    const Eigen::Vector3d& point = points[size_t(i)];
    const double length = (point - eye).norm();
    if (length <= margin_m) return;
    blocked[size_t(i)] = tree_.crosses(eye, point + (eye - point) * (margin_m / length));
  });
  return std::vector<bool>(blocked.begin(), blocked.end());
}

}  // namespace tega::tracking
