#include "tega/uvd/uv_layout.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "tega/core/error.h"
#include "tega/uvd/uv_lookup.h"

namespace tega::uvd {
namespace {

// Lookups are exact at any resolution; a coarse grid builds in a fraction of
// the default's time, and these two lookups are built at every model's start.
constexpr double kOverlapTestResolution = 128;

// Whether a UV centroid of one group's triangles lies inside the other's.
bool centroids_inside(const Mesh& mesh, const std::vector<int32_t>& of, const std::vector<int32_t>& in) {
  const UvTriangleLookup other(mesh, {kOverlapTestResolution, 0.1}, in);
  at::Tensor centroids = at::empty({static_cast<int64_t>(of.size()), 2}, at::kDouble);
  auto c = centroids.accessor<double, 2>();
  for (size_t i = 0; i < of.size(); ++i)
    for (int axis = 0; axis < 2; ++axis) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += mesh.uvs(mesh.uv_faces(of[i], k), axis);
      c[static_cast<int64_t>(i)][axis] = sum / 3;
    }
  return (other.lookup(centroids).distance == 0).any().item<bool>();
}

}  // namespace

SurfaceAreas surface_areas(const Mesh& mesh, const std::vector<int32_t>& faces) {
  SurfaceAreas a;
  for (const int32_t f : faces) {
    const Eigen::Vector3f p = mesh.positions.row(mesh.faces(f, 0)), q = mesh.positions.row(mesh.faces(f, 1)),
                          r = mesh.positions.row(mesh.faces(f, 2));
    a.world += 0.5 * (q - p).cross(r - p).norm();
    const Eigen::Vector2f s = mesh.uvs.row(mesh.uv_faces(f, 0)), t = mesh.uvs.row(mesh.uv_faces(f, 1)),
                          u = mesh.uvs.row(mesh.uv_faces(f, 2));
    const Eigen::Vector2f e1 = t - s, e2 = u - s;
    a.uv += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  return a;
}

Mesh with_part_laid_apart(const Mesh& mesh, const std::vector<int32_t>& part) {
  if (!mesh.has_uvs()) throw Error("the template has no UVs to lay out");
  std::vector<bool> in_part(mesh.num_faces(), false);
  for (const int32_t f : part) {
    if (f < 0 || f >= mesh.num_faces())
      throw Error("face " + std::to_string(f) + " of the part to lay apart is out of range (the template has " +
                  std::to_string(mesh.num_faces()) + " faces)");
    in_part[f] = true;
  }
  std::vector<int32_t> moved, rest;
  for (int32_t f = 0; f < mesh.num_faces(); ++f) (in_part[f] ? moved : rest).push_back(f);
  const SurfaceAreas a_moved = surface_areas(mesh, moved), a_rest = surface_areas(mesh, rest);
  if (a_moved.uv <= 0 || a_rest.uv <= 0) return mesh;
  if (!centroids_inside(mesh, moved, rest) && !centroids_inside(mesh, rest, moved)) return mesh;
  const double scale = a_moved.world > 0 ? std::sqrt((a_rest.uv / a_rest.world) / (a_moved.uv / a_moved.world)) : 1.0;
  Eigen::Vector2f rest_min = Eigen::Vector2f::Constant(INFINITY), rest_max = -rest_min, moved_min = rest_min;
  for (const int32_t f : rest)
    for (int k = 0; k < 3; ++k) {
      rest_min = rest_min.cwiseMin(mesh.uvs.row(mesh.uv_faces(f, k)).transpose());
      rest_max = rest_max.cwiseMax(mesh.uvs.row(mesh.uv_faces(f, k)).transpose());
    }
  for (const int32_t f : moved)
    for (int k = 0; k < 3; ++k) moved_min = moved_min.cwiseMin(mesh.uvs.row(mesh.uv_faces(f, k)).transpose());
  const Eigen::Vector2f origin(rest_max.x() + (rest_max - rest_min).maxCoeff() / 16, rest_min.y());

  // The moved triangles get UV entries of their own, appended in order of first use.
  Mesh out = mesh;
  std::vector<int32_t> copy_of(mesh.uvs.rows(), -1);
  std::vector<Eigen::Vector2f> added;
  for (const int32_t f : moved)
    for (int k = 0; k < 3; ++k) {
      const int32_t t = mesh.uv_faces(f, k);
      if (copy_of[t] < 0) {
        copy_of[t] = static_cast<int32_t>(mesh.uvs.rows() + added.size());
        added.push_back(origin + scale * (mesh.uvs.row(t).transpose() - moved_min));
      }
      out.uv_faces(f, k) = copy_of[t];
    }
  out.uvs.conservativeResize(mesh.uvs.rows() + static_cast<Eigen::Index>(added.size()), 2);
  for (size_t i = 0; i < added.size(); ++i) out.uvs.row(mesh.uvs.rows() + static_cast<Eigen::Index>(i)) = added[i];
  // The old entries only the moved triangles used stay behind unused, so no index shifts.
  return out;
}

}  // namespace tega::uvd
