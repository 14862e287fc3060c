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

}  // namespace
}  // namespace tega
