// Open3D stays in this file: its headers are heavy.
#include "tega/mvs/surface.h"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/utility/Logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/mesh_tools.h"
#include "tega/core/thread_pool.h"

namespace tega::mvs {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Runs body(i) for i in [0, n) on the pool in chunks: one index at a time, the
// pool's shared counter would cost more than a KD-tree query.
template <class Body>
void for_each_index(ThreadPool& pool, size_t n, Body body) {
  constexpr size_t kChunk = 4096;
  pool.parallel_for(0, int64_t((n + kChunk - 1) / kChunk), [&](int64_t chunk) {
    std::vector<int> index(1);
    std::vector<double> squared_distance(1);
    for (size_t i = size_t(chunk) * kChunk; i < std::min(n, size_t(chunk + 1) * kChunk); ++i)
      body(i, index, squared_distance);
  });
}

open3d::geometry::PointCloud to_open3d(const OrientedPointCloud& cloud) {
  open3d::geometry::PointCloud out;
  out.points_.reserve(size_t(cloud.size()));
  out.normals_.reserve(size_t(cloud.size()));
  for (int i = 0; i < cloud.size(); ++i) {
    out.points_.push_back(cloud.points.row(i).transpose().cast<double>());
    out.normals_.push_back(cloud.normals.row(i).transpose().cast<double>());
  }
  return out;
}

void trim_low_density(open3d::geometry::TriangleMesh& mesh, const std::vector<double>& densities, double quantile) {
  if (quantile <= 0 || densities.empty()) return;
  std::vector<double> sorted = densities;
  const size_t k = std::min(sorted.size() - 1, size_t(quantile * double(sorted.size())));
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
  const double threshold = sorted[k];
  std::vector<bool> remove(densities.size());
  for (size_t i = 0; i < densities.size(); ++i) remove[i] = densities[i] < threshold;
  mesh.RemoveVerticesByMask(remove);
}

// A face counts as supported when one of its vertices lies within the
// distance of a point: faces are far smaller than the distance.
void trim_far_from_points(open3d::geometry::TriangleMesh& mesh, const open3d::geometry::KDTreeFlann& tree,
                          double max_distance, ThreadPool& pool) {
  if (max_distance <= 0) return;
  std::vector<uint8_t> near(mesh.vertices_.size());
  for_each_index(pool, mesh.vertices_.size(), [&](size_t v, std::vector<int>& index, std::vector<double>& distance) {
    near[v] = tree.SearchKNN(mesh.vertices_[v], 1, index, distance) == 1 && distance[0] <= max_distance * max_distance;
  });
  std::vector<bool> remove(mesh.triangles_.size());
  for (size_t f = 0; f < mesh.triangles_.size(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles_[f];
    remove[f] = !near[size_t(t[0])] && !near[size_t(t[1])] && !near[size_t(t[2])];
  }
  mesh.RemoveTrianglesByMask(remove);
}

// Through core's mesh tools (OpenMesh), which tracking shares.
Mesh trim_small_components(const Mesh& mesh, double min_share) {
  if (min_share <= 0 || mesh.num_faces() == 0) return mesh;
  const int largest = keep_largest_component(mesh, "the Poisson surface").num_faces();
  return remove_small_components(mesh, int(std::ceil(min_share * largest)), "the Poisson surface");
}

// Poisson's winding follows the normals it was given, but its convention is
// Open3D's; vote with the cloud's normals so that faces wind counter-clockwise
// seen from outside.
void orient_like_points(open3d::geometry::TriangleMesh& mesh, const open3d::geometry::PointCloud& points,
                        const open3d::geometry::KDTreeFlann& tree, ThreadPool& pool) {
  std::vector<double> votes(mesh.triangles_.size(), 0.0);
  for_each_index(pool, mesh.triangles_.size(), [&](size_t f, std::vector<int>& index, std::vector<double>& distance) {
    const Eigen::Vector3i& t = mesh.triangles_[f];
    const Eigen::Vector3d& a = mesh.vertices_[size_t(t[0])];
    const Eigen::Vector3d& b = mesh.vertices_[size_t(t[1])];
    const Eigen::Vector3d& c = mesh.vertices_[size_t(t[2])];
    if (tree.SearchKNN(Eigen::Vector3d((a + b + c) / 3), 1, index, distance) == 1)
      votes[f] = (b - a).cross(c - a).dot(points.normals_[size_t(index[0])]);
  });
  double agreement = 0;  // summed in order: the same for any thread count
  for (double vote : votes) agreement += vote;
  if (agreement < 0)
    for (Eigen::Vector3i& t : mesh.triangles_) std::swap(t[1], t[2]);
}

Mesh to_tega(const open3d::geometry::TriangleMesh& mesh) {
  Mesh out;
  out.positions.resize(Eigen::Index(mesh.vertices_.size()), 3);
  for (size_t v = 0; v < mesh.vertices_.size(); ++v)
    out.positions.row(Eigen::Index(v)) = mesh.vertices_[v].transpose().cast<float>();
  out.faces.resize(Eigen::Index(mesh.triangles_.size()), 3);
  for (size_t f = 0; f < mesh.triangles_.size(); ++f) out.faces.row(Eigen::Index(f)) = mesh.triangles_[f].transpose();
  return out;
}

}  // namespace

Mesh reconstruct_surface(const OrientedPointCloud& cloud, const SurfaceOptions& options) {
  if (cloud.size() == 0) throw Error("surface reconstruction: the point cloud is empty");
  if (cloud.normals.rows() != cloud.points.rows())
    throw Error("surface reconstruction: the point cloud has no normals (" + std::to_string(cloud.normals.rows()) +
                " for " + std::to_string(cloud.size()) + " points)");
  // Open3D's Poisson prints its progress at Info level, on stdout.
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Warning);
  const auto start = std::chrono::steady_clock::now();
  const open3d::geometry::PointCloud points = to_open3d(cloud);
  auto [mesh, densities] = open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(
      points, size_t(options.poisson_depth), 0.0f, float(options.poisson_scale), false,
      options.poisson_threads > 0 ? options.poisson_threads : -1);
  const double poisson_s = seconds_since(start);

  const open3d::geometry::KDTreeFlann tree(points);
  ThreadPool pool(options.threads);
  trim_low_density(*mesh, densities, options.trim_density_quantile);
  trim_far_from_points(*mesh, tree, options.trim_distance_m, pool);
  mesh->RemoveUnreferencedVertices();
  orient_like_points(*mesh, points, tree, pool);
  const double trim_s = seconds_since(start) - poisson_s;
  Mesh result = trim_small_components(to_tega(*mesh), options.min_component_share);
  logging::debug("surface: Poisson %.2f s, trimming %.2f s, components %.2f s", poisson_s, trim_s,
                 seconds_since(start) - poisson_s - trim_s);
  return result;
}

}  // namespace tega::mvs
