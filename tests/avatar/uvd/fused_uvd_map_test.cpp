// uvd_to_world's fused evaluation against the composed tensor ops it takes
// for a posed mesh that requires grad: values and gradients w.r.t. uvd in
// double, through projection and through binding; float against double.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "fused_test_support.h"
#include "tega/uvd/uvd_map.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

using test::row_relative_error;

struct MappedSeamedMesh {
  Mesh mesh = test::seamed_mesh();
  UvTriangleLookup lookup{mesh, {64, 0.1}};
  PosedMesh posed = pose(lookup, test::to_tensor(test::posed_vertices(mesh)));
  // The same mesh, taking gradients: mapped with the composed tensor ops.
  PosedMesh differentiable{posed.vertices.clone().requires_grad_(true), posed.normals};

  std::vector<int> valid_faces() const {
    std::vector<int> faces;
    for (int f = 0; f < lookup.num_triangles(); ++f)
      if (lookup.uv_area()[f].item<double>() > 0) faces.push_back(f);
    return faces;
  }
};

struct Mapped {
  at::Tensor xyz, jacobian, triangle, grad_uvd;
};

// uvd_to_world and the gradient w.r.t. uvd of Σ weight_xyz·xyz + Σ weight_jacobian·J;
// an undefined weight leaves that output out of the loss.
Mapped map(const at::Tensor& uvd_in, const PosedMesh& mesh, const UvTriangleLookup& lookup, const at::Tensor& bound,
           const at::Tensor& weight_xyz, const at::Tensor& weight_jacobian) {
  const at::Tensor uvd = uvd_in.detach().clone().requires_grad_(true);
  const UvdMapping m = uvd_to_world(uvd, mesh, lookup, bound);
  std::vector<at::Tensor> terms;
  if (weight_xyz.defined()) terms.push_back((m.xyz * weight_xyz.to(uvd.options())).sum());
  if (weight_jacobian.defined()) terms.push_back((m.jacobian * weight_jacobian.to(uvd.options())).sum());
  const at::Tensor grad = torch::autograd::grad({at::stack(terms).sum()}, {uvd})[0];
  return {m.xyz.detach(), m.jacobian.detach(), m.triangle, grad};
}

at::Tensor with_depth(const at::Tensor& uv, unsigned seed) {
  auto generator = at::detail::createCPUGenerator(seed);
  return at::cat({uv, (at::rand({uv.size(0), 1}, generator, at::kDouble) * 2 - 1) * 0.1}, 1);
}

void expect_same_mapping(const MappedSeamedMesh& s, const at::Tensor& uvd, const at::Tensor& bound) {
  const int64_t n = uvd.size(0);
  const at::Tensor wx = at::randn({n, 3}, at::kDouble), wj = at::randn({n, 3, 3}, at::kDouble);
  const std::pair<at::Tensor, at::Tensor> losses[] = {{wx, wj}, {wx, at::Tensor()}, {at::Tensor(), wj}};
  for (const auto& [weight_xyz, weight_jacobian] : losses) {
    const Mapped fused = map(uvd, s.posed, s.lookup, bound, weight_xyz, weight_jacobian);
    const Mapped reference = map(uvd, s.differentiable, s.lookup, bound, weight_xyz, weight_jacobian);
    EXPECT_TRUE(fused.triangle.equal(reference.triangle));
    EXPECT_EQ(fused.triangle.scalar_type(), at::kLong);
    EXPECT_LT(row_relative_error(fused.xyz, reference.xyz), 1e-12);
    EXPECT_LT(row_relative_error(fused.jacobian, reference.jacobian), 1e-12);
    EXPECT_LT(row_relative_error(fused.grad_uvd, reference.grad_uvd), 1e-10)
        << "loss on xyz " << weight_xyz.defined() << ", on J " << weight_jacobian.defined();
  }
}

TEST(FusedUvdMap, MatchesTheComposedOpsThroughTheLookup) {
  MappedSeamedMesh s;
  // Points inside their triangles (edges included), and uniformly random
  // ones, most of them off the layout and projected onto it.
  const auto inside = test::points_in_faces(s.mesh, s.valid_faces(), 5, 0.0, 1).uv;
  const auto random = at::rand({3000, 2}, at::detail::createCPUGenerator(2), at::kDouble) * 1.1 - 0.05;
  expect_same_mapping(s, with_depth(at::cat({inside, random}), 3), at::Tensor());
}

TEST(FusedUvdMap, MatchesTheComposedOpsWhenBound) {
  MappedSeamedMesh s;
  const auto points = test::points_in_faces(s.mesh, s.valid_faces(), 5, 0.0, 4);
  const auto face = at::tensor(std::vector<int64_t>(points.face.begin(), points.face.end()));
  // Moved off their triangles, which then extrapolate affinely.
  const auto moved = points.uv + at::randn({face.size(0), 2}, at::detail::createCPUGenerator(5), at::kDouble) * 0.03;
  expect_same_mapping(s, with_depth(moved, 6), face);
}

TEST(FusedUvdMap, FloatMatchesDouble) {
  MappedSeamedMesh s;
  const int64_t n = 100000;
  const auto random = at::rand({n, 2}, at::detail::createCPUGenerator(7), at::kDouble) * 1.1 - 0.05;
  // Both precisions in the triangles that the double lookup picks, at its projected uv.
  const UvHit hit = s.lookup.lookup(random);
  const auto uvd = with_depth(hit.uv, 8);
  const at::Tensor wx = at::randn({n, 3}, at::kDouble), wj = at::randn({n, 3, 3}, at::kDouble);
  const PosedMesh single{s.posed.vertices.to(at::kFloat), s.posed.normals.to(at::kFloat)};
  const Mapped f = map(uvd.to(at::kFloat), single, s.lookup, hit.triangle, wx, wj);
  const Mapped d = map(uvd, s.posed, s.lookup, hit.triangle, wx, wj);
  ASSERT_EQ(f.xyz.scalar_type(), at::kFloat);
  EXPECT_LT(row_relative_error(f.xyz, d.xyz), 1e-4);
  EXPECT_LT(row_relative_error(f.jacobian, d.jacobian), 1e-4);
  EXPECT_LT(row_relative_error(f.grad_uvd, d.grad_uvd), 1e-3);
}

TEST(FusedUvdMap, RejectsBoundTrianglesOutOfRange) {
  MappedSeamedMesh s;
  const auto uvd = at::zeros({2, 3}, at::kDouble);
  EXPECT_THROW(uvd_to_world(uvd, s.posed, s.lookup, at::tensor({int64_t(0), s.lookup.num_triangles()})), c10::Error);
  EXPECT_THROW(uvd_to_world(uvd, s.posed, s.lookup, at::tensor({int64_t(-1), int64_t(0)})), c10::Error);
}

}  // namespace
}  // namespace tega::uvd
