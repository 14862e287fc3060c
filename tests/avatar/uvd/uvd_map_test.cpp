#include "tega/uvd/uvd_map.h"

#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "test_support.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

using test::seamed_mesh;

std::vector<int> valid_faces(const UvTriangleLookup& lookup) {
  std::vector<int> faces;
  const auto area = lookup.uv_area();
  for (int f = 0; f < area.size(0); ++f)
    if (area[f].item<double>() > 0) faces.push_back(f);
  return faces;
}

at::Tensor with_depth(const at::Tensor& uv, double max_depth, unsigned seed) {
  auto generator = at::detail::createCPUGenerator(seed);
  const auto d = (at::rand({uv.size(0), 1}, generator, at::kDouble) * 2 - 1) * max_depth;
  return at::cat({uv, d}, 1);
}

// Central differences of F along each uvd axis: [N,3,3] with columns ∂/∂u, ∂/∂v, ∂/∂d.
at::Tensor finite_difference_jacobian(const at::Tensor& uvd, const PosedMesh& posed, const UvTriangleLookup& lookup,
                                      double h, const at::Tensor& bound = at::Tensor()) {
  std::vector<at::Tensor> columns;
  for (int k = 0; k < 3; ++k) {
    auto step = at::zeros_like(uvd);
    step.select(1, k).fill_(h);
    columns.push_back((uvd_to_world(uvd + step, posed, lookup, bound).xyz -
                       uvd_to_world(uvd - step, posed, lookup, bound).xyz) /
                      (2 * h));
  }
  return at::stack(columns, 2);
}

void expect_close(const at::Tensor& actual, const at::Tensor& expected, double relative) {
  const double scale = std::max(1.0, expected.abs().max().item<double>());
  EXPECT_LT((actual - expected).abs().max().item<double>(), relative * scale);
}

struct PosedSeamedMesh {
  Mesh mesh = seamed_mesh();
  UvTriangleLookup lookup{mesh, {64, 0.1}};
  Eigen::MatrixXd vertices = test::posed_vertices(mesh);
  PosedMesh posed = pose(lookup, test::to_tensor(vertices));
};

TEST(UvdMap, VertexNormalsAreAreaWeightedAcrossSeams) {
  PosedSeamedMesh s;
  EXPECT_TRUE(s.posed.normals.allclose(test::to_tensor(test::reference_normals(s.vertices, s.mesh)), 0, 1e-12));
}

TEST(UvdMap, PositionsFollowTheDefinition) {
  PosedSeamedMesh s;
  const auto points = test::points_in_faces(s.mesh, valid_faces(s.lookup), 5, 0.0, 1);
  const auto uvd = with_depth(points.uv, 0.1, 2);
  const UvdMapping map = uvd_to_world(uvd, s.posed, s.lookup);
  const Eigen::MatrixXd normals = test::reference_normals(s.vertices, s.mesh);
  for (int64_t i = 0; i < uvd.size(0); ++i) {
    ASSERT_EQ(map.triangle[i].item<int64_t>(), points.face[i]);
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      const double b = points.barycentrics[i][c].item<double>();
      p += b * s.vertices.row(s.mesh.faces(points.face[i], c)).transpose();
      m += b * normals.row(s.mesh.faces(points.face[i], c)).transpose();
    }
    const Eigen::Vector3d expected = p + uvd[i][2].item<double>() * m.normalized();
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(map.xyz[i][k].item<double>(), expected[k], 1e-12);
  }
}

TEST(UvdMap, JacobianMatchesFiniteDifferences) {
  PosedSeamedMesh s;
  // Well inside the triangles, and within 1e-3 (in barycentrics) of their edges, seams included.
  for (auto [margin, h] : {std::pair{0.02, 1e-6}, std::pair{1e-3, 1e-8}}) {
    const auto points = test::points_in_faces(s.mesh, valid_faces(s.lookup), 5, margin, 3);
    const auto uvd = with_depth(points.uv, 0.1, 4);
    const UvdMapping map = uvd_to_world(uvd, s.posed, s.lookup);
    expect_close(map.jacobian, finite_difference_jacobian(uvd, s.posed, s.lookup, h), 1e-6);
  }
}

TEST(UvdMap, AutogradGradientIsTheJacobian) {
  PosedSeamedMesh s;
  const auto points = test::points_in_faces(s.mesh, valid_faces(s.lookup), 3, 0.0, 5);
  const auto uvd = with_depth(points.uv, 0.1, 6);
  const auto reference = uvd_to_world(uvd, s.posed, s.lookup).jacobian;
  for (int k = 0; k < 3; ++k) {
    const auto x = uvd.clone().set_requires_grad(true);
    uvd_to_world(x, s.posed, s.lookup).xyz.select(1, k).sum().backward();
    EXPECT_TRUE(x.grad().allclose(reference.select(1, k), 0, 1e-12)) << "row " << k;
  }
}

// ∂J/∂uvd reaches the covariance J Σ Jᵀ: autograd through J matches finite differences.
TEST(UvdMap, JacobianDerivativeMatchesFiniteDifferences) {
  PosedSeamedMesh s;
  const auto points = test::points_in_faces(s.mesh, valid_faces(s.lookup), 5, 0.02, 7);
  const auto uvd = with_depth(points.uv, 0.1, 8);
  const auto weight = at::randn({uvd.size(0), 3, 3}, at::kDouble);
  auto per_point = [&](const at::Tensor& x) {
    return (uvd_to_world(x, s.posed, s.lookup).jacobian * weight).sum({1, 2});
  };
  const auto x = uvd.clone().set_requires_grad(true);
  per_point(x).sum().backward();
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    auto step = at::zeros_like(uvd);
    step.select(1, k).fill_(h);
    const auto numeric = (per_point(uvd + step) - per_point(uvd - step)) / (2 * h);
    expect_close(x.grad().select(1, k), numeric, 1e-5);
  }
}

// Queries outside every triangle: mapped through their closest valid point.
TEST(UvdMap, ProjectedPointsUseTheirClosestValidPoint) {
  PosedSeamedMesh s;
  const auto uv = at::rand({4000, 2}, at::kDouble) * 1.1 - 0.05;
  const UvHit hit = s.lookup.lookup(uv);
  const auto outside = hit.distance > 1e-3;
  ASSERT_GT(outside.sum().item<int64_t>(), 500);
  const auto uvd = with_depth(uv.index({outside}), 0.1, 9);
  const auto valid_uv = hit.uv.index({outside}), triangle = hit.triangle.index({outside});
  const UvdMapping map = uvd_to_world(uvd, s.posed, s.lookup);
  const UvdMapping on_valid = uvd_to_world(at::cat({valid_uv, uvd.slice(1, 2, 3)}, 1), s.posed, s.lookup, triangle);
  EXPECT_TRUE(map.xyz.allclose(on_valid.xyz, 0, 1e-12));
  EXPECT_TRUE(map.jacobian.allclose(on_valid.jacobian, 0, 1e-12));

  // Where the closest point is inside an edge, sliding the query along that
  // edge slides the point the same way: F's derivative along it is J's.
  const auto b = hit.barycentrics.index({outside});
  const auto on_edge = ((b < 1e-12).sum(1) == 1) & (std::get<0>(b.max(1)) < 0.95);
  ASSERT_GT(on_edge.sum().item<int64_t>(), 50);
  const auto q = uvd.index({on_edge}), t = triangle.index({on_edge}), bb = b.index({on_edge});
  const auto corners = at::empty({t.size(0), 3, 2}, at::kDouble);
  for (int64_t i = 0; i < t.size(0); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto uv_c = test::uv_corner(s.mesh, static_cast<int>(t[i].item<int64_t>()), c);
      corners[i][c][0] = uv_c.x();
      corners[i][c][1] = uv_c.y();
    }
  // The edge spans the two corners with nonzero barycentrics.
  const auto zero_corner = std::get<1>(bb.min(1));
  const auto first = corners.gather(1, ((zero_corner + 1) % 3).view({-1, 1, 1}).expand({-1, 1, 2})).squeeze(1);
  const auto second = corners.gather(1, ((zero_corner + 2) % 3).view({-1, 1, 1}).expand({-1, 1, 2})).squeeze(1);
  const auto tangent = (second - first) / (second - first).norm(2, 1, true);
  const double h = 1e-7;
  const auto step = at::cat({tangent * h, at::zeros({t.size(0), 1}, at::kDouble)}, 1);
  const auto numeric = (uvd_to_world(q + step, s.posed, s.lookup).xyz - uvd_to_world(q - step, s.posed, s.lookup).xyz) / (2 * h);
  const auto analytic = map.jacobian.index({on_edge}).slice(2, 0, 2).matmul(tangent.unsqueeze(-1)).squeeze(-1);
  expect_close(analytic, numeric, 1e-6);
  // The gradient passes straight through the projection.
  const auto x = uvd.clone().set_requires_grad(true);
  uvd_to_world(x, s.posed, s.lookup).xyz.select(1, 0).sum().backward();
  EXPECT_TRUE(x.grad().allclose(map.jacobian.select(1, 0), 0, 1e-12));
}

TEST(UvdMap, BindingKeepsTheGivenTriangleAndExtrapolates) {
  PosedSeamedMesh s;
  const auto points = test::points_in_faces(s.mesh, valid_faces(s.lookup), 2, 0.05, 10);
  const auto face = at::tensor(std::vector<int64_t>(points.face.begin(), points.face.end()));
  const auto uvd = with_depth(points.uv, 0.1, 11);
  // Inside their triangles, binding changes nothing.
  const UvdMapping inside = uvd_to_world(uvd, s.posed, s.lookup, face);
  EXPECT_TRUE(inside.triangle.equal(face));
  EXPECT_TRUE(inside.xyz.allclose(uvd_to_world(uvd, s.posed, s.lookup).xyz, 0, 1e-12));

  // Pushed out of them, the points stay on their triangle's affine extension.
  const Eigen::MatrixXd normals = test::reference_normals(s.vertices, s.mesh);
  auto moved = uvd.clone();
  for (int64_t i = 0; i < uvd.size(0); ++i) {
    // Beyond corner 0: half as far past it as the point was before it.
    const Eigen::Vector2d c0 = test::uv_corner(s.mesh, points.face[i], 0);
    const Eigen::Vector2d uv(uvd[i][0].item<double>(), uvd[i][1].item<double>());
    const Eigen::Vector2d beyond = c0 + 0.5 * (c0 - uv);
    moved[i][0] = beyond.x();
    moved[i][1] = beyond.y();
  }
  const UvdMapping bound = uvd_to_world(moved, s.posed, s.lookup, face);
  EXPECT_TRUE(bound.triangle.equal(face));
  for (int64_t i = 0; i < uvd.size(0); ++i) {
    const int f = points.face[i];
    Eigen::Matrix2d e;
    e.col(0) = test::uv_corner(s.mesh, f, 1) - test::uv_corner(s.mesh, f, 0);
    e.col(1) = test::uv_corner(s.mesh, f, 2) - test::uv_corner(s.mesh, f, 0);
    const Eigen::Vector2d uv(moved[i][0].item<double>(), moved[i][1].item<double>());
    const Eigen::Vector2d b12 = e.inverse() * (uv - test::uv_corner(s.mesh, f, 0));
    const double b[3] = {1 - b12.sum(), b12.x(), b12.y()};
    ASSERT_LT(std::min({b[0], b[1], b[2]}), 0);  // really outside
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      p += b[c] * s.vertices.row(s.mesh.faces(f, c)).transpose();
      m += b[c] * normals.row(s.mesh.faces(f, c)).transpose();
    }
    const Eigen::Vector3d expected = p + moved[i][2].item<double>() * m.normalized();
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(bound.xyz[i][k].item<double>(), expected[k], 1e-10);
  }
  expect_close(bound.jacobian, finite_difference_jacobian(moved, s.posed, s.lookup, 1e-6, face), 1e-6);
}

TEST(UvdMap, IctFaceKitJacobianMatchesFiniteDifferences) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  at::set_num_threads(2);
  const Mesh mesh = read_obj(ict / "generic_neutral_mesh.obj");
  const UvTriangleLookup lookup(mesh, {512, 0.1}, test::ict_head_faces(mesh));
  // Centimetres to metres, then the same non-rigid pose as the procedural tests.
  Mesh metres = mesh;
  metres.positions *= 0.01f;
  const PosedMesh posed = pose(lookup, test::to_tensor(test::posed_vertices(metres)));
  const auto uv = lookup.sample_uniform(3000, 12).to(at::kDouble);
  // Keep points 1e-3 (in barycentrics) from the edges, so the steps stay in the triangle.
  const auto keep = std::get<0>(lookup.lookup(uv).barycentrics.min(1)) > 1e-3;
  const auto uvd = with_depth(uv.index({keep}), 0.005, 13);
  ASSERT_GT(uvd.size(0), 2000);
  const UvdMapping map = uvd_to_world(uvd, posed, lookup);
  expect_close(map.jacobian, finite_difference_jacobian(uvd, posed, lookup, 1e-8), 1e-5);
}

}  // namespace
}  // namespace tega::uvd
