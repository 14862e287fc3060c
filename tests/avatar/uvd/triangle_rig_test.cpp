// GaussianAvatars' rigging: the frame of a known triangle, the similarity
// motion it follows, the shear it does not, and its gradients.

#include "tega/uvd/triangle_rig.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>

namespace tega::uvd {
namespace {

at::Tensor doubles(std::initializer_list<double> values, at::IntArrayRef shape) {
  return at::tensor(std::vector<double>(values), at::kDouble).view(shape).clone();
}

// Two triangles sharing an edge, not in a coordinate plane.
struct TwoTriangles {
  at::Tensor vertices = doubles({0.1, 0.0, 0.2, 2.1, 0.3, 0.1, 0.0, 1.2, 0.5, 1.8, 1.9, 0.9}, {4, 3});
  at::Tensor faces = at::tensor(std::vector<int64_t>{0, 1, 2, 1, 3, 2}, at::kLong).view({2, 3});
  PosedMesh posed() const { return {vertices, at::zeros_like(vertices)}; }
};

TEST(TriangleRig, FrameOfARightTriangle) {
  const at::Tensor vertices = doubles({0, 0, 0, 2, 0, 0, 0, 1, 0}, {3, 3});
  const at::Tensor faces = at::tensor(std::vector<int64_t>{0, 1, 2}, at::kLong).view({1, 3});
  const TriangleFrames f = triangle_frames(vertices, faces);
  EXPECT_TRUE(f.origin.allclose(doubles({2.0 / 3, 1.0 / 3, 0}, {1, 3}), 0, 1e-12));
  EXPECT_TRUE(f.rotation.allclose(at::eye(3, at::kDouble).unsqueeze(0), 0, 1e-12));
  EXPECT_NEAR(f.scale.item<double>(), 1.5, 1e-12);  // (base 2 + height 1) / 2

  const at::Tensor local = doubles({0, 0, 0, 1, 0, 0, 0, 0, 2}, {3, 3});
  const at::Tensor triangle = at::zeros({3}, at::kLong);
  const UvdMapping m = rigged_to_world(local, triangle, {vertices, at::zeros_like(vertices)}, faces);
  EXPECT_TRUE(m.xyz.allclose(doubles({2.0 / 3, 1.0 / 3, 0, 2.0 / 3 + 1.5, 1.0 / 3, 0, 2.0 / 3, 1.0 / 3, 3}, {3, 3}),
                             0, 1e-12));
  EXPECT_TRUE(m.jacobian.allclose(1.5 * at::eye(3, at::kDouble).expand({3, 3, 3}), 0, 1e-12));
}

TEST(TriangleRig, FramesAreRightHandedAndOrthonormal) {
  const TwoTriangles t;
  const TriangleFrames f = triangle_frames(t.vertices, t.faces);
  const at::Tensor gram = f.rotation.transpose(1, 2).matmul(f.rotation);
  EXPECT_TRUE(gram.allclose(at::eye(3, at::kDouble).expand({2, 3, 3}), 0, 1e-12));
  EXPECT_TRUE(at::det(f.rotation).allclose(at::ones({2}, at::kDouble), 0, 1e-12));
}

// A rotation, uniform scale and translation of the mesh carries every rigged
// point and its Jacobian along: GA's Gaussians follow the triangle's
// similarity motion.
TEST(TriangleRig, FollowsASimilarityOfTheMesh) {
  const TwoTriangles t;
  const at::Tensor local = doubles({0.3, -0.2, 0.1, -1.5, 0.7, 0.4, 0.0, 0.0, -0.6}, {3, 3});
  const at::Tensor triangle = at::tensor(std::vector<int64_t>{0, 1, 1}, at::kLong);
  const UvdMapping before = rigged_to_world(local, triangle, t.posed(), t.faces);

  const double c = std::cos(0.7), s = std::sin(0.7), sigma = 1.7;
  const at::Tensor rotation = doubles({c, -s, 0, s * 0.6, c * 0.6, -0.8, s * 0.8, c * 0.8, 0.6}, {3, 3});
  const at::Tensor shift = doubles({0.4, -2.0, 1.1}, {1, 3});
  const at::Tensor moved = sigma * t.vertices.matmul(rotation.t()) + shift;
  const UvdMapping after = rigged_to_world(local, triangle, {moved, at::zeros_like(moved)}, t.faces);

  EXPECT_TRUE(after.xyz.allclose(sigma * before.xyz.matmul(rotation.t()) + shift, 0, 1e-10));
  EXPECT_TRUE(after.jacobian.allclose(sigma * rotation.matmul(before.jacobian), 0, 1e-10));
}

// Unlike TeGA's UVD map, the rig does not shear: a point on the normal stays
// on the (new) normal, at a distance set by k, however the triangle shears.
TEST(TriangleRig, DoesNotFollowShear) {
  const at::Tensor faces = at::tensor(std::vector<int64_t>{0, 1, 2}, at::kLong).view({1, 3});
  const at::Tensor sheared = doubles({0, 0, 0, 2, 0, 0, 1.5, 1, 0}, {3, 3});
  const at::Tensor local = doubles({0, 0, 1}, {1, 3});
  const UvdMapping m = rigged_to_world(local, at::zeros({1}, at::kLong), {sheared, at::zeros_like(sheared)}, faces);
  EXPECT_TRUE(m.xyz.allclose(doubles({3.5 / 3, 1.0 / 3, 1.5}, {1, 3}), 0, 1e-12));
  EXPECT_TRUE(m.jacobian.allclose(1.5 * at::eye(3, at::kDouble).unsqueeze(0), 0, 1e-12));
}

// ∂x/∂μ is the returned Jacobian, and the mesh's gradient matches central
// differences (the rig is differentiable in the vertices).
TEST(TriangleRig, GradientsMatchTheJacobianAndFiniteDifferences) {
  const TwoTriangles t;
  const at::Tensor local = doubles({0.3, -0.2, 0.1, -1.5, 0.7, 0.4}, {2, 3}).requires_grad_(true);
  const at::Tensor triangle = at::tensor(std::vector<int64_t>{0, 1}, at::kLong);
  const at::Tensor weights = doubles({0.2, -0.7, 1.1, 0.5, 0.9, -0.3}, {2, 3});
  const at::Tensor vertices = t.vertices.clone().requires_grad_(true);
  const UvdMapping m = rigged_to_world(local, triangle, {vertices, at::zeros_like(vertices)}, t.faces);
  (m.xyz * weights).sum().backward();
  const at::Tensor expected = m.jacobian.detach().transpose(1, 2).matmul(weights.unsqueeze(2)).squeeze(2);
  EXPECT_TRUE(local.grad().allclose(expected, 0, 1e-12));

  const double h = 1e-6;
  for (int64_t i = 0; i < vertices.numel(); ++i) {
    at::Tensor plus = t.vertices.clone(), minus = t.vertices.clone();
    plus.view({-1})[i] += h;
    minus.view({-1})[i] -= h;
    const auto value = [&](const at::Tensor& v) {
      return (rigged_to_world(local.detach(), triangle, {v, at::zeros_like(v)}, t.faces).xyz * weights)
          .sum()
          .item<double>();
    };
    EXPECT_NEAR(vertices.grad().view({-1})[i].item<double>(), (value(plus) - value(minus)) / (2 * h), 1e-6) << i;
  }
}

TEST(TriangleRig, RejectsATriangleOutOfRange) {
  const TwoTriangles t;
  EXPECT_THROW(rigged_to_world(at::zeros({1, 3}, at::kDouble), at::full({1}, 2, at::kLong), t.posed(), t.faces),
               c10::Error);
}

}  // namespace
}  // namespace tega::uvd
