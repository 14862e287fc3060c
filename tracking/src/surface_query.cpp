#include "surface_query.h"

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

namespace tega::tracking {

namespace o3c = open3d::core;

struct SurfaceQuery::Scene {
  open3d::t::geometry::RaycastingScene scene;
};

SurfaceQuery::SurfaceQuery(const Mesh& surface) : scene_(std::make_unique<Scene>()) {
  const int64_t n = surface.num_vertices(), m = surface.num_faces();
  std::vector<float> positions(surface.positions.data(), surface.positions.data() + 3 * n);
  std::vector<uint32_t> faces(3 * m);
  for (int64_t f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) faces[3 * f + k] = static_cast<uint32_t>(surface.faces(f, k));
  scene_->scene.AddTriangles(o3c::Tensor(positions, {n, 3}, o3c::Float32),
                             o3c::Tensor(faces, {m, 3}, o3c::UInt32));
}

SurfaceQuery::~SurfaceQuery() = default;

std::vector<ClosestPoint> SurfaceQuery::closest(const std::vector<Eigen::Vector3d>& points) const {
  const int64_t n = static_cast<int64_t>(points.size());
  if (n == 0) return {};
  std::vector<float> query(3 * n);
  for (int64_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) query[3 * i + k] = static_cast<float>(points[i][k]);
  auto result = scene_->scene.ComputeClosestPoints(o3c::Tensor(query, {n, 3}, o3c::Float32));
  const o3c::Tensor found = result.at("points").Contiguous();
  const o3c::Tensor normals = result.at("primitive_normals").Contiguous();
  const float* p = found.GetDataPtr<float>();
  const float* q = normals.GetDataPtr<float>();
  std::vector<ClosestPoint> out(points.size());
  for (int64_t i = 0; i < n; ++i) {
    out[i].point = Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    out[i].normal = Eigen::Vector3d(q[3 * i], q[3 * i + 1], q[3 * i + 2]).normalized();
  }
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
  const o3c::Tensor hits = scene_->scene.TestOcclusions(o3c::Tensor(rays, {n, 6}, o3c::Float32), 0.f, tfar).Contiguous();
  const bool* h = hits.GetDataPtr<bool>();
  return std::vector<bool>(h, h + n);
}

}  // namespace tega::tracking
