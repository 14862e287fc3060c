#include "tega/uvd/covariance.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "tega/uvd/uvd_map.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

Eigen::Matrix3d matrix(const at::Tensor& t, int64_t i) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = t[i][r][c].item<double>();
  return m;
}

void expect_symmetric_psd(const at::Tensor& covariance) {
  EXPECT_TRUE(covariance.equal(covariance.transpose(1, 2)));
  for (int64_t i = 0; i < covariance.size(0); ++i) {
    const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(matrix(covariance, i)).eigenvalues();
    ASSERT_GE(eigenvalues.minCoeff(), -1e-12 * std::max(1.0, eigenvalues.maxCoeff()));
  }
}

struct Inputs {
  at::Tensor jacobian, scale, quaternion;
};
Inputs random_inputs(int64_t n, uint64_t seed) {
  auto g = at::detail::createCPUGenerator(seed);
  return {at::randn({n, 3, 3}, g, at::kDouble), at::rand({n, 3}, g, at::kDouble) * 0.1 + 1e-4,
          at::randn({n, 4}, g, at::kDouble)};
}

TEST(Covariance, RotationFromQuaternionMatchesEigen) {
  const Inputs in = random_inputs(50, 1);
  const auto rotation = rotation_from_quaternion(in.quaternion);
  for (int64_t i = 0; i < 50; ++i) {
    const Eigen::Quaterniond q(in.quaternion[i][0].item<double>(), in.quaternion[i][1].item<double>(),
                               in.quaternion[i][2].item<double>(), in.quaternion[i][3].item<double>());
    EXPECT_TRUE(matrix(rotation, i).isApprox(q.normalized().toRotationMatrix(), 1e-12));
  }
}

TEST(Covariance, WorldCovarianceIsTheExplicitProduct) {
  const Inputs in = random_inputs(100, 2);
  const auto a = at::randn({100, 3, 3}, at::kDouble);
  const auto sigma = a.matmul(a.transpose(1, 2));
  const auto world = world_covariance(in.jacobian, sigma);
  expect_symmetric_psd(world);
  for (int64_t i = 0; i < 100; ++i) {
    const Eigen::Matrix3d j = matrix(in.jacobian, i);
    EXPECT_TRUE(matrix(world, i).isApprox(j * matrix(sigma, i) * j.transpose(), 1e-12));
  }
}

TEST(Covariance, ScaleRotationFormAgreesWithTheMatrixForm) {
  const Inputs in = random_inputs(100, 3);
  const auto sigma = covariance_from_scale_rotation(in.scale, in.quaternion);
  for (int64_t i = 0; i < 100; ++i) {
    const Eigen::Matrix3d r = matrix(rotation_from_quaternion(in.quaternion), i);
    const Eigen::Vector3d s(in.scale[i][0].item<double>(), in.scale[i][1].item<double>(), in.scale[i][2].item<double>());
    EXPECT_TRUE(matrix(sigma, i).isApprox(r * s.cwiseAbs2().asDiagonal() * r.transpose(), 1e-12));
  }
  const auto world = world_covariance(in.jacobian, in.scale, in.quaternion);
  expect_symmetric_psd(world);
  EXPECT_TRUE(world.allclose(world_covariance(in.jacobian, sigma), 1e-10, 1e-14));
}

TEST(Covariance, PackedFormRoundTrips) {
  const auto a = at::randn({20, 3, 3}, at::kDouble);
  const auto sigma = a.matmul(a.transpose(1, 2));
  const auto packed = pack_symmetric(sigma);
  ASSERT_EQ(packed.size(1), 6);
  EXPECT_EQ(packed[4][1].item<double>(), sigma[4][0][1].item<double>());  // xy
  EXPECT_EQ(packed[4][4].item<double>(), sigma[4][1][2].item<double>());  // yz
  EXPECT_TRUE(unpack_symmetric(packed).equal(sigma));
}

TEST(Covariance, BatchedMatmulMatchesBmm) {
  const at::Tensor a = at::randn({17, 3, 3}, at::kDouble), b = at::randn({17, 3, 2}, at::kDouble);
  EXPECT_TRUE(at::allclose(batched_matmul(a, b), at::bmm(a, b), 1e-14, 1e-14));
  EXPECT_TRUE(at::allclose(batched_matmul(b, b.transpose(1, 2)), at::bmm(b, b.transpose(1, 2)), 1e-14, 1e-14));
}

TEST(Covariance, MeshJacobiansGiveSymmetricPsdCovariances) {
  const Mesh mesh = test::seamed_mesh();
  const UvTriangleLookup lookup(mesh, {64, 0.1});
  const PosedMesh posed = pose(lookup, test::to_tensor(test::posed_vertices(mesh)));
  const auto uv = lookup.sample_uniform(500, 4).to(at::kDouble);
  const auto uvd = at::cat({uv, at::rand({500, 1}, at::kDouble) * 0.2 - 0.1}, 1);
  const auto jacobian = uvd_to_world(uvd, posed, lookup).jacobian;
  const Inputs in = random_inputs(500, 5);
  expect_symmetric_psd(world_covariance(jacobian, in.scale, in.quaternion));
  // A Gaussian thin in u and v and long in d points along the surface normal (J's third column).
  const auto needle = world_covariance(jacobian, at::tensor({1e-6, 1e-6, 1e-2}, at::kDouble).expand({500, 3}),
                                       at::tensor({1.0, 0.0, 0.0, 0.0}, at::kDouble).expand({500, 4}));
  const auto normal = jacobian.select(2, 2);
  const auto along = (normal.unsqueeze(1).matmul(needle).matmul(normal.unsqueeze(-1))).view({-1});
  EXPECT_TRUE(along.allclose(at::full({500}, 1e-4, at::kDouble), 1e-4, 0));
}

}  // namespace
}  // namespace tega::uvd
