#include "surface_query.h"

#include "tega/core/thread_pool.h"

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

namespace tega::tracking {

namespace o3c = open3d::core;

struct SurfaceQuery::Scene {
  open3d::t::geometry::RaycastingScene scene;
};

SurfaceQuery::SurfaceQuery(const Mesh& surface)
    : surface_(surface), tree_(surface), face_normals_(surface.num_faces(), 3) {
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Eigen::Vector3f a = surface.positions.row(surface.faces(f, 0)), b = surface.positions.row(surface.faces(f, 1)),
                          c = surface.positions.row(surface.faces(f, 2));
    face_normals_.row(f) = (b - a).cross(c - a).normalized().transpose();
  }
}

// Frames tracked without image terms never ask about occlusion: the
// ray-casting scene is built on the first question only.
SurfaceQuery::Scene& SurfaceQuery::scene() const {
  std::call_once(scene_built_, [this] {
    scene_ = std::make_unique<Scene>();
    const int64_t n = surface_.num_vertices(), m = surface_.num_faces();
    std::vector<float> positions(surface_.positions.data(), surface_.positions.data() + 3 * n);
    std::vector<uint32_t> faces(3 * m);
    for (int64_t f = 0; f < m; ++f)
      for (int k = 0; k < 3; ++k) faces[3 * f + k] = static_cast<uint32_t>(surface_.faces(f, k));
    scene_->scene.AddTriangles(o3c::Tensor(positions, {n, 3}, o3c::Float32), o3c::Tensor(faces, {m, 3}, o3c::UInt32));
  });
  return *scene_;
}

SurfaceQuery::~SurfaceQuery() = default;

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
  const int64_t n = static_cast<int64_t>(points.size());
  if (n == 0) return {};
  // Rays with unnormalised directions eye -> point: t = 1 at the point.
  std::vector<float> rays(6 * n);
  double longest = 0;
  for (int64_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = points[i] - eye;
    longest = std::max(longest, d.norm());
    for (int k = 0; k < 3; ++k) {
      rays[6 * i + k] = static_cast<float>(eye[k]);
      rays[6 * i + 3 + k] = static_cast<float>(d[k]);
    }
  }
  // One tfar for all rays: the margin measured on the nearest scale that
  // matters, the longest segment (the others get a slightly larger margin).
  const float tfar = static_cast<float>(1.0 - margin_m / std::max(longest, 1e-9));
  const o3c::Tensor hits = scene().scene.TestOcclusions(o3c::Tensor(rays, {n, 6}, o3c::Float32), 0.f, tfar).Contiguous();
  const bool* h = hits.GetDataPtr<bool>();
  return std::vector<bool>(h, h + n);
}

}  // namespace tega::tracking
