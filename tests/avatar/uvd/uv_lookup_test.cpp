#include "tega/uvd/uv_lookup.h"

#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tega/core/error.h"
#include "test_support.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

using test::points_in_faces;
using test::seamed_mesh;

std::vector<int> valid_faces(const Mesh& m) {
  std::vector<int> faces;
  for (int f = 0; f < m.num_faces(); ++f)
    if (test::uv_area(m, f) > 1e-12) faces.push_back(f);
  return faces;
}

// Every point sampled inside a triangle comes back with that triangle, zero
// distance, and barycentrics that reproduce it.
void expect_inside_points_found(const Mesh& mesh, const UvTriangleLookup& lookup, const std::vector<int>& faces,
                                int per_face) {
  const auto points = points_in_faces(mesh, faces, per_face, 1e-3, 11);
  const UvHit hit = lookup.lookup(points.uv);
  auto tri = hit.triangle.accessor<int64_t, 1>();
  auto b = hit.barycentrics.accessor<double, 2>();
  const auto expected_b = points.barycentrics.accessor<double, 2>();
  int64_t mismatches = 0;
  for (int64_t i = 0; i < points.uv.size(0); ++i) {
    if (tri[i] != points.face[i]) {
      ++mismatches;
      continue;
    }
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(b[i][c], expected_b[i][c], 1e-9) << "point " << i;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_LT(hit.distance.max().item<double>(), 1e-12);
  EXPECT_TRUE(hit.uv.equal(points.uv));
}

// Queries anywhere in the grid's domain: the distance is the brute-force
// distance to the nearest triangle, and the returned point lies on the
// returned triangle at that distance.
void expect_nearest_points(const Mesh& mesh, const UvTriangleLookup& lookup, int n, double tolerance,
                           at::ScalarType dtype, double u_min = -0.05, double u_max = 1.05) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(u_min, u_max), v(0.0, 1.0);
  auto query = at::empty({n, 2}, at::kDouble);
  for (int i = 0; i < n; ++i) {
    query[i][0] = u(rng);
    query[i][1] = v(rng);
  }
  const UvHit hit = lookup.lookup(query.to(dtype));
  const auto point = hit.uv.to(at::kDouble), b = hit.barycentrics.to(at::kDouble);
  auto p_acc = point.accessor<double, 2>();
  auto b_acc = b.accessor<double, 2>();
  auto q_acc = query.accessor<double, 2>();
  auto tri = hit.triangle.accessor<int64_t, 1>();
  const auto distance = hit.distance.to(at::kDouble);
  auto d_acc = distance.accessor<double, 1>();
  int outside = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d q(q_acc[i][0], q_acc[i][1]), p(p_acc[i][0], p_acc[i][1]);
    const double expected = test::nearest_uv_distance(mesh, q);
    outside += expected > 0;
    ASSERT_NEAR(d_acc[i], expected, tolerance) << "query " << q.transpose();
    ASSERT_NEAR((q - p).norm(), expected, tolerance);
    Eigen::Vector2d from_b = Eigen::Vector2d::Zero();
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(b_acc[i][c], -tolerance);
      from_b += b_acc[i][c] * test::uv_corner(mesh, static_cast<int>(tri[i]), c);
    }
    ASSERT_NEAR((from_b - p).norm(), 0, tolerance);
  }
  EXPECT_GT(outside, n / 10);  // the layout has holes: many queries must be projected
  EXPECT_LT(outside, n);
}

TEST(UvLookup, InsidePointsFindTheirTriangleAtAnyResolution) {
  const Mesh mesh = seamed_mesh();
  for (double resolution : {1.0, 7.0, 64.0, 512.0}) {
    SCOPED_TRACE(resolution);
    expect_inside_points_found(mesh, UvTriangleLookup(mesh, {resolution, 0.1}), valid_faces(mesh), 20);
  }
}

TEST(UvLookup, OutsidePointsGoToTheNearestTriangleAtAnyResolution) {
  const Mesh mesh = seamed_mesh();
  for (double resolution : {1.0, 5.0, 40.0, 300.0}) {
    SCOPED_TRACE(resolution);
    expect_nearest_points(mesh, UvTriangleLookup(mesh, {resolution, 0.1}), 3000, 1e-12, at::kDouble);
  }
}

TEST(UvLookup, Float32QueriesAreExactUpToRounding) {
  const Mesh mesh = seamed_mesh();
  expect_nearest_points(mesh, UvTriangleLookup(mesh, {128, 0.1}), 3000, 2e-6, at::kFloat);
}

TEST(UvLookup, QueriesBeyondTheGridStillLandOnATriangle) {
  const Mesh mesh = seamed_mesh();
  const UvTriangleLookup lookup(mesh, {64, 0.1});
  const auto query = at::tensor({-3.0, 0.5, 0.5, 7.0, 2.0, -2.0, 0.3, 0.5}, at::kDouble).view({4, 2});
  const UvHit hit = lookup.lookup(query);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d p(hit.uv[i][0].item<double>(), hit.uv[i][1].item<double>());
    EXPECT_NEAR(test::distance_to_uv_triangle(mesh, static_cast<int>(hit.triangle[i].item<int64_t>()), p), 0, 1e-12);
    EXPECT_GE(hit.distance[i].item<double>(), test::nearest_uv_distance(mesh, {query[i][0].item<double>(),
                                                                              query[i][1].item<double>()}) - 1e-12);
  }
}

TEST(UvLookup, ProjectionKeepsValidUvsAndIsIdempotent) {
  const Mesh mesh = seamed_mesh();
  const UvTriangleLookup lookup(mesh, {32, 0.1});
  const auto query = at::rand({2000, 2}, at::kDouble) * 1.1 - 0.05;
  const auto once = lookup.project_to_valid_uv(query);
  EXPECT_TRUE(lookup.project_to_valid_uv(once).allclose(once, 0, 1e-14));
  const auto valid = lookup.lookup(query).distance == 0;
  EXPECT_GT(valid.sum().item<int64_t>(), 0);
  EXPECT_TRUE(once.index({valid}).equal(query.index({valid})));
}

TEST(UvLookup, ZeroAreaTrianglesAreNeverReturned) {
  const Mesh mesh = seamed_mesh();
  const UvTriangleLookup lookup(mesh, {16, 0.1});
  EXPECT_EQ(lookup.uv_area()[test::degenerate_face_of_seamed_mesh(mesh)].item<double>(), 0);
  // Along the degenerate triangle's segment, and all over the domain.
  auto t = at::linspace(0, 1, 101, at::kDouble).unsqueeze(1);
  const auto segment = at::tensor({0.8, 0.2}, at::kDouble) + t * at::tensor({0.1, 0.1}, at::kDouble);
  const auto query = at::cat({segment, at::rand({5000, 2}, at::kDouble)});
  EXPECT_FALSE((lookup.lookup(query).triangle == test::degenerate_face_of_seamed_mesh(mesh)).any().item<bool>());
}

TEST(UvLookup, BarycentricsInAGivenTriangleExtrapolate) {
  const Mesh mesh = seamed_mesh();
  const UvTriangleLookup lookup(mesh, {16, 0.1});
  const auto triangle = at::tensor({0, 5, 100}, at::kLong);
  // Corner 0 plus twice the edge to corner 1: barycentrics (-1, 2, 0).
  auto uv = at::empty({3, 2}, at::kDouble);
  for (int i = 0; i < 3; ++i) {
    const int f = static_cast<int>(triangle[i].item<int64_t>());
    const Eigen::Vector2d p = test::uv_corner(mesh, f, 0) + 2 * (test::uv_corner(mesh, f, 1) - test::uv_corner(mesh, f, 0));
    uv[i][0] = p.x();
    uv[i][1] = p.y();
  }
  const auto expected = at::tensor({-1.0, 2.0, 0.0}, at::kDouble).expand({3, 3});
  EXPECT_TRUE(lookup.barycentrics_in(uv, triangle).allclose(expected, 0, 1e-9));
}

TEST(UvLookup, UniformSamplesAreValidAndAreaUniform) {
  const Mesh mesh = seamed_mesh();
  const UvTriangleLookup lookup(mesh, {64, 0.1});
  const int64_t n = 200000;
  const auto uv = lookup.sample_uniform(n, 5);
  ASSERT_EQ(uv.scalar_type(), at::kFloat);
  EXPECT_TRUE(uv.equal(lookup.sample_uniform(n, 5)));
  const UvHit hit = lookup.lookup(uv.to(at::kDouble));
  EXPECT_LT(hit.distance.max().item<double>(), 1e-6);
  // Counts per triangle follow the UV area (a 5-sigma band around the binomial mean).
  const auto counts = at::bincount(hit.triangle, {}, lookup.num_triangles()).to(at::kDouble);
  const auto expected = lookup.uv_area() / lookup.uv_area().sum() * n;
  const auto z = (counts - expected).abs() / expected.clamp_min(1).sqrt();
  EXPECT_LT(z.max().item<double>(), 5);
  // Uniform within triangles: the corner region b0 > 1/2 holds a quarter of the area.
  const double corner_fraction = (hit.barycentrics.select(1, 0) > 0.5).to(at::kDouble).mean().item<double>();
  EXPECT_NEAR(corner_fraction, 0.25, 0.005);
}

TEST(UvLookup, RejectsMeshesWithoutUvs) {
  Mesh mesh = seamed_mesh();
  mesh.uvs.resize(0, 2);
  mesh.uv_faces.resize(0, 3);
  EXPECT_THROW(UvTriangleLookup{mesh}, tega::Error);
}

TEST(UvLookup, IctFaceKitLookupIsExact) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  at::set_num_threads(2);
  const Mesh full = read_obj(ict / "generic_neutral_mesh.obj");
  // The face and the head-and-neck (polygons [0, 11144)) have UV islands of
  // their own; the eyes and eye meshes overlap the face's tile.
  Mesh mesh = full;
  const auto head = test::ict_head_faces(full);
  for (int f = 0; f < full.num_faces(); ++f)
    if (!std::binary_search(head.begin(), head.end(), f)) mesh.uv_faces.row(f).setZero();  // zero area
  const UvTriangleLookup lookup(full, {1024, 0.1}, head);
  std::vector<int> sampled;
  for (int32_t f : head)
    if (f % 7 == 0) sampled.push_back(f);
  expect_inside_points_found(mesh, lookup, sampled, 2);
  expect_nearest_points(mesh, lookup, 300, 1e-12, at::kDouble, -0.05, 2.05);
}

}  // namespace
}  // namespace tega::uvd
