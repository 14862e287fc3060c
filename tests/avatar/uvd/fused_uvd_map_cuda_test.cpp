// uvd_to_world's fused evaluation: the CUDA kernels against the CPU loops
// (values and gradients w.r.t. uvd), bound and through the lookup; skips
// where there is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/cuda.h>

#include "fused_test_support.h"
#include "tega/uvd/uvd_map.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

using test::row_relative_error;

struct Mapped {
  at::Tensor xyz, jacobian, triangle, grad_uvd;  // on the CPU
};

// uvd [N,3] double, mapped in `dtype` on `device`, with the gradient of Σ wx·xyz + Σ wj·J.
Mapped map(const Mesh& mesh, const UvTriangleLookup& lookup, const at::Tensor& uvd_in, const at::Tensor& bound,
           const at::Tensor& wx, const at::Tensor& wj, at::ScalarType dtype, const at::Device& device) {
  const UvTriangleLookup on_device = lookup.to(device);
  const PosedMesh posed = pose(on_device, test::to_tensor(test::posed_vertices(mesh)).to(device, dtype));
  const at::Tensor uvd = uvd_in.to(device, dtype).requires_grad_(true);
  const UvdMapping m = uvd_to_world(uvd, posed, on_device, bound.defined() ? bound.to(device) : bound);
  const at::Tensor loss = (m.xyz * wx.to(device, dtype)).sum() + (m.jacobian * wj.to(device, dtype)).sum();
  const at::Tensor grad = torch::autograd::grad({loss}, {uvd})[0];
  return {m.xyz.detach().cpu(), m.jacobian.detach().cpu(), m.triangle.cpu(), grad.cpu()};
}

void expect_parity(const Mesh& mesh, const UvTriangleLookup& lookup, const at::Tensor& uvd, const at::Tensor& bound) {
  const at::Device gpu(at::kCUDA, 0);
  const int64_t n = uvd.size(0);
  const at::Tensor wx = at::randn({n, 3}, at::kDouble), wj = at::randn({n, 3, 3}, at::kDouble);
  const Mapped cpu = map(mesh, lookup, uvd, bound, wx, wj, at::kDouble, at::kCPU);
  const Mapped single = map(mesh, lookup, uvd, bound, wx, wj, at::kFloat, gpu);
  const Mapped exact = map(mesh, lookup, uvd, bound, wx, wj, at::kDouble, gpu);
  EXPECT_TRUE(single.triangle.equal(cpu.triangle));
  EXPECT_TRUE(exact.triangle.equal(cpu.triangle));
  EXPECT_LT(row_relative_error(single.xyz, cpu.xyz), 1e-4);
  EXPECT_LT(row_relative_error(single.jacobian, cpu.jacobian), 1e-4);
  EXPECT_LT(row_relative_error(single.grad_uvd, cpu.grad_uvd), 1e-3);
  EXPECT_LT(row_relative_error(exact.xyz, cpu.xyz), 1e-10);
  EXPECT_LT(row_relative_error(exact.jacobian, cpu.jacobian), 1e-10);
  EXPECT_LT(row_relative_error(exact.grad_uvd, cpu.grad_uvd), 1e-10);
}

at::Tensor with_depth(const at::Tensor& uv, unsigned seed) {
  auto generator = at::detail::createCPUGenerator(seed);
  return at::cat({uv, (at::rand({uv.size(0), 1}, generator, at::kDouble) * 2 - 1) * 0.1}, 1);
}

std::vector<int> valid_faces(const UvTriangleLookup& lookup) {
  std::vector<int> faces;
  for (int f = 0; f < lookup.num_triangles(); ++f)
    if (lookup.uv_area()[f].item<double>() > 0) faces.push_back(f);
  return faces;
}

// 100K uniformly random uvs, most of them off the layout, bound to the
// triangles the CPU lookup picks, at its projected uv: every device and
// precision evaluates the same triangles.
TEST(FusedUvdMapCuda, BoundMatchesCpu) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const Mesh mesh = test::seamed_mesh();
  const UvTriangleLookup lookup(mesh, {64, 0.1});
  const auto uv = at::rand({100000, 2}, at::detail::createCPUGenerator(1), at::kDouble) * 1.1 - 0.05;
  const UvHit hit = lookup.lookup(uv);
  expect_parity(mesh, lookup, with_depth(hit.uv, 2), hit.triangle);
}

// 100K points well inside their triangles, so that the lookups agree in float.
TEST(FusedUvdMapCuda, LookupMatchesCpu) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const Mesh mesh = test::seamed_mesh();
  const UvTriangleLookup lookup(mesh, {64, 0.1});
  const std::vector<int> faces = valid_faces(lookup);
  const auto points = test::points_in_faces(mesh, faces, int(100000 / faces.size()) + 1, 0.01, 3);
  expect_parity(mesh, lookup, with_depth(points.uv, 4), at::Tensor());
}

}  // namespace
}  // namespace tega::uvd
