// The uv lookup's CUDA kernel against the CPU loop: the same nearest points
// for queries inside, between and beyond the UV islands, in both precisions.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/cuda.h>

#include "tega/uvd/uv_lookup.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

void expect_parity(at::ScalarType dtype, double tolerance) {
  const Mesh mesh = test::seamed_mesh();
  const UvTriangleLookup cpu(mesh, {64, 0.1});
  const UvTriangleLookup gpu = cpu.to(at::kCUDA);
  // Most of [-0.2, 1.2]² is off the layout (holes, seams, beyond the grid's margin).
  const int64_t n = 200000;
  const at::Tensor query = (at::rand({n, 2}, at::detail::createCPUGenerator(5), at::kDouble) * 1.4 - 0.2).to(dtype);
  const UvHit expected = cpu.lookup(query);
  const UvHit actual_device = gpu.lookup(query.cuda());
  const UvHit actual{actual_device.triangle.cpu(), actual_device.barycentrics.cpu(), actual_device.uv.cpu(),
                     actual_device.distance.cpu()};

  // Where rounding picks the other triangle of a shared edge or an equally near one, both answers are right.
  const int64_t same = actual.triangle.eq(expected.triangle).sum().item<int64_t>();
  EXPECT_GE(same, n - n / 1000);
  EXPECT_LT((actual.distance - expected.distance).abs().max().item<double>(), tolerance);
  EXPECT_GT(expected.distance.gt(0).sum().item<int64_t>(), n / 4);

  // The same points, but for a few that rounding moves along an edge of the same triangle.
  const at::Tensor kept = actual.triangle.eq(expected.triangle);
  const auto moved = [&](const at::Tensor& a, const at::Tensor& b, double limit) {
    return ((a - b).abs().amax(1) > limit).logical_and(kept).sum().item<int64_t>();
  };
  EXPECT_LE(moved(actual.uv, expected.uv, tolerance), n / 1000);
  EXPECT_LE(moved(actual.barycentrics, expected.barycentrics, tolerance * 10), n / 1000);
  // Every answer's barycentrics rebuild its point on its own triangle.
  const auto tri = actual.triangle.accessor<int64_t, 1>();
  const at::Tensor b = actual.barycentrics.to(at::kDouble), p = actual.uv.to(at::kDouble);
  const auto b_acc = b.accessor<double, 2>();
  const auto p_acc = p.accessor<double, 2>();
  for (int64_t i = 0; i < n; ++i) {
    Eigen::Vector2d from_b = Eigen::Vector2d::Zero();
    for (int c = 0; c < 3; ++c) from_b += b_acc[i][c] * test::uv_corner(mesh, int(tri[i]), c);
    ASSERT_NEAR(from_b.x(), p_acc[i][0], tolerance * 10) << "query " << i;
    ASSERT_NEAR(from_b.y(), p_acc[i][1], tolerance * 10) << "query " << i;
  }
}

TEST(UvLookupCuda, MatchesTheCpuInDouble) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  expect_parity(at::kDouble, 1e-12);
}

TEST(UvLookupCuda, MatchesTheCpuInFloat) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  expect_parity(at::kFloat, 2e-6);
}

}  // namespace
}  // namespace tega::uvd
