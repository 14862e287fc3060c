#include "tega/core/triangle_distance_tree.h"

#include <gtest/gtest.h>

#include <random>

namespace tega {
namespace {

// A bumpy grid of triangles: every query's answer is checked against all of them.
Mesh bumpy_grid(int n) {
  Mesh mesh;
  mesh.positions.resize((n + 1) * (n + 1), 3);
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      mesh.positions.row(y * (n + 1) + x) << float(x) / n, float(y) / n, 0.05f * std::sin(7.0f * x / n) * std::cos(5.0f * y / n);
  mesh.faces.resize(2 * n * n, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.faces.row(2 * (y * n + x)) << a, b, d;
      mesh.faces.row(2 * (y * n + x) + 1) << a, d, c;
    }
  return mesh;
}

TEST(TriangleDistanceTree, ClosestPointAndFaceMatchBruteForce) {
  const Mesh mesh = bumpy_grid(24);
  const TriangleDistanceTree tree(mesh);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 1.2), h(-0.3, 0.3);
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), h(rng));
    double best = 1e9;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto v = [&](int k) { return mesh.positions.row(mesh.faces(f, k)).cast<double>().transpose().eval(); };
      best = std::min(best, (closest_point_on_triangle(p, v(0), v(1), v(2)) - p).norm());
    }
    const auto found = tree.closest(p);
    EXPECT_NEAR(found.distance, best, 1e-12);
    EXPECT_NEAR((found.point - p).norm(), best, 1e-12);
    ASSERT_GE(found.face, 0);
    const auto v = [&](int k) { return mesh.positions.row(mesh.faces(found.face, k)).cast<double>().transpose().eval(); };
    EXPECT_NEAR((closest_point_on_triangle(p, v(0), v(1), v(2)) - p).norm(), best, 1e-12);
  }
  EXPECT_EQ(TriangleDistanceTree(Mesh{}).closest(Eigen::Vector3d::Zero()).face, -1);
}

// Lines of sight over the grid (|z| <= 0.05 inside 0 <= x, y <= 1): a
// segment from above to below it always crosses it; one that stays above, ends
// short of it or passes beside it never does.
TEST(TriangleDistanceTree, SegmentsCrossTheSurfaceExactlyWhenTheyPassThroughIt) {
  const Mesh mesh = bumpy_grid(24);
  const TriangleDistanceTree tree(mesh);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> inside(0.01, 0.99), beside(1.05, 2.0);
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d above(inside(rng), inside(rng), 1), below(inside(rng), inside(rng), -1);
    EXPECT_TRUE(tree.crosses(above, below));
    EXPECT_TRUE(tree.crosses(below, above));
    EXPECT_FALSE(tree.crosses(above, Eigen::Vector3d(below.x(), below.y(), 0.06)));
    EXPECT_FALSE(tree.crosses(above, Eigen::Vector3d(inside(rng), inside(rng), 0.5)));
    EXPECT_FALSE(tree.crosses(Eigen::Vector3d(beside(rng), inside(rng), 1), Eigen::Vector3d(beside(rng), inside(rng), -1)));
  }
  EXPECT_FALSE(tree.crosses(Eigen::Vector3d(-0.5, 0.5, 0), Eigen::Vector3d(-0.1, 0.5, 0)));  // in its plane, beside it
  EXPECT_FALSE(TriangleDistanceTree(Mesh{}).crosses(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()));
  // A single triangle, the segment's ends excluded.
  Mesh one;
  one.positions.resize(3, 3);
  one.positions << -1, -1, 0, 1, -1, 0, 0, 1, 0;
  one.faces.resize(1, 3);
  one.faces << 0, 1, 2;
  const TriangleDistanceTree single(one);
  EXPECT_TRUE(single.crosses(Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, 1)));
  EXPECT_FALSE(single.crosses(Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, -0.01)));
  EXPECT_FALSE(single.crosses(Eigen::Vector3d(5, 5, -1), Eigen::Vector3d(5, 5, 1)));
  EXPECT_FALSE(single.crosses(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.5, 0, 1)));  // parallel, above
}

}  // namespace
}  // namespace tega
