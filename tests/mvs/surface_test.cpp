#include "tega/mvs/surface.h"

#include <gtest/gtest.h>

#include <map>

#include "sphere_scene.h"
#include "tega/core/error.h"

namespace tega::mvs {
namespace {

using test::kRadius;

// Octree depth 8 resolves a 0.2 m sphere to ~1 mm cells, enough for these
// checks in a fraction of depth 9's time. One thread: OpenMP's waiting
// threads slow Poisson down by orders of magnitude on a loaded machine.
SurfaceOptions test_options() {
  SurfaceOptions options;
  options.poisson_depth = 8;
  options.threads = 1;
  return options;
}

double max_distance_to_sphere(const Mesh& mesh) {
  double worst = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    worst = std::max(worst, std::abs(mesh.positions.row(v).cast<double>().norm() - kRadius));
  return worst;
}

TEST(Surface, SphereCloudGivesAClosedOutwardSphere) {
  SurfaceOptions options = test_options();
  // Cutting a fixed share of vertices by density would open holes in a
  // surface that the points support everywhere.
  options.trim_density_quantile = 0;
  const Mesh mesh = reconstruct_surface(test::sphere_cloud(20000, kRadius), options);
  ASSERT_GT(mesh.num_faces(), 10000);
  EXPECT_LT(max_distance_to_sphere(mesh), 0.0005);

  std::map<std::pair<int, int>, int> edge_uses;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) ++edge_uses[std::minmax(mesh.faces(f, k), mesh.faces(f, (k + 1) % 3))];
  int open_edges = 0;
  for (const auto& [edge, uses] : edge_uses) open_edges += uses != 2;
  EXPECT_EQ(open_edges, 0);

  const Vertices normals = mesh.vertex_normals();
  int inward = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) inward += normals.row(v).dot(mesh.positions.row(v)) <= 0;
  EXPECT_EQ(inward, 0);
}

// Poisson on one thread (the default): a frame meshed again, as a resumed
// take does, gives the same mesh.
TEST(Surface, TheSameCloudGivesTheSameMesh) {
  SurfaceOptions options = test_options();
  options.threads = 0;
  const OrientedPointCloud cloud = test::sphere_cloud(20000, kRadius, 0.0);
  const Mesh first = reconstruct_surface(cloud, options);
  for (int again = 0; again < 3; ++again) {
    const Mesh mesh = reconstruct_surface(cloud, options);
    ASSERT_EQ(mesh.num_faces(), first.num_faces());
    EXPECT_EQ(mesh.positions, first.positions);
    EXPECT_EQ(mesh.faces, first.faces);
  }
}

TEST(Surface, HemisphereCloudIsTrimmedToTheHemisphere) {
  const Mesh mesh = reconstruct_surface(test::sphere_cloud(20000, kRadius, 0.0), test_options());
  ASSERT_GT(mesh.num_faces(), 5000);
  // Distance from each vertex to the sampled hemisphere (z >= 0 of the sphere).
  double worst = 0, lowest = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p = mesh.positions.row(v).cast<double>();
    const Eigen::Vector3d on_sphere = p.z() >= 0
                                          ? Eigen::Vector3d(kRadius * p.normalized())
                                          : Eigen::Vector3d(kRadius * Eigen::Vector3d(p.x(), p.y(), 0).normalized());
    worst = std::max(worst, (p - on_sphere).norm());
    lowest = std::min(lowest, p.z());
  }
  EXPECT_LT(worst, 0.004);
  EXPECT_GT(lowest, -0.004);
  // Enough of the hemisphere is kept: its area is 2 pi r^2.
  double area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.positions.row(mesh.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = mesh.positions.row(mesh.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = mesh.positions.row(mesh.faces(f, 2)).cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  EXPECT_GT(area, 0.85 * 2 * std::numbers::pi * kRadius * kRadius);
}

TEST(Surface, SmallComponentsAreRemoved) {
  OrientedPointCloud cloud = test::sphere_cloud(20000, kRadius);
  const OrientedPointCloud speck = test::sphere_cloud(300, 0.01);
  const Eigen::Index n = cloud.size();
  cloud.points.conservativeResize(n + speck.size(), 3);
  cloud.normals.conservativeResize(n + speck.size(), 3);
  cloud.points.bottomRows(speck.size()) = speck.points.rowwise() + Eigen::RowVector3f(0.2f, 0, 0);
  cloud.normals.bottomRows(speck.size()) = speck.normals;
  SurfaceOptions options = test_options();
  options.poisson_depth = 7;
  options.trim_density_quantile = 0;
  const Mesh mesh = reconstruct_surface(cloud, options);
  ASSERT_GT(mesh.num_faces(), 1000);
  EXPECT_LT(mesh.positions.col(0).maxCoeff(), kRadius + 0.001);
}

TEST(Surface, EmptyCloudOrNoNormalsIsAnError) {
  EXPECT_THROW(reconstruct_surface(OrientedPointCloud{}, SurfaceOptions{}), Error);
  OrientedPointCloud cloud = test::sphere_cloud(100, kRadius);
  cloud.normals.resize(0, 3);
  EXPECT_THROW(reconstruct_surface(cloud, SurfaceOptions{}), Error);
}

}  // namespace
}  // namespace tega::mvs
