// world_covariance_packed against the composed tensor ops it replaces in the
// trainer (values and gradients, in double), and float against double, on
// the CPU.
#include "tega/uvd/fused_covariance.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include "fused_test_support.h"
#include "tega/uvd/covariance.h"

namespace tega::uvd {
namespace {

using test::row_relative_error;

struct Leaves {
  at::Tensor jacobian, quaternion, log_scale;
};

Leaves leaves(const test::CovarianceInputs& in, at::ScalarType dtype = at::kDouble) {
  return {in.jacobian.to(dtype).requires_grad_(true), in.quaternion.to(dtype).requires_grad_(true),
          in.log_scale.to(dtype).requires_grad_(true)};
}

PackedCovariance composed(const Leaves& in) {
  const at::Tensor rotation = rotation_from_quaternion(in.quaternion);
  const at::Tensor jacobian_rotation = batched_matmul(in.jacobian, rotation);
  const at::Tensor shape = jacobian_rotation * in.log_scale.exp().unsqueeze(1);
  return {pack_symmetric(batched_matmul(shape, shape.transpose(1, 2))), jacobian_rotation.detach().norm(2, 1)};
}

std::vector<at::Tensor> gradients(const at::Tensor& covariance, const at::Tensor& weight, const Leaves& in) {
  return torch::autograd::grad({(covariance * weight.to(covariance.scalar_type())).sum()},
                               {in.jacobian, in.quaternion, in.log_scale});
}

TEST(FusedCovariance, MatchesTheComposedOps) {
  const auto inputs = test::random_covariance_inputs(2000, 1);
  const at::Tensor weight = at::randn({2000, 6}, at::kDouble);
  const Leaves a = leaves(inputs), b = leaves(inputs);
  const PackedCovariance fused = world_covariance_packed(a.jacobian, a.quaternion, a.log_scale);
  const PackedCovariance reference = composed(b);
  EXPECT_LT(row_relative_error(fused.covariance, reference.covariance), 1e-12);
  EXPECT_LT(row_relative_error(fused.std_per_scale, reference.std_per_scale), 1e-12);
  EXPECT_FALSE(fused.std_per_scale.requires_grad());
  const auto g = gradients(fused.covariance, weight, a), r = gradients(reference.covariance, weight, b);
  const char* names[] = {"jacobian", "quaternion", "log_scale"};
  for (int k = 0; k < 3; ++k) EXPECT_LT(row_relative_error(g[k], r[k]), 1e-10) << names[k];
}

TEST(FusedCovariance, FloatMatchesDouble) {
  const auto inputs = test::random_covariance_inputs(100000, 2);
  const at::Tensor weight = at::randn({100000, 6}, at::kDouble);
  const Leaves f = leaves(inputs, at::kFloat), d = leaves(inputs);
  const PackedCovariance single = world_covariance_packed(f.jacobian, f.quaternion, f.log_scale);
  const PackedCovariance exact = world_covariance_packed(d.jacobian, d.quaternion, d.log_scale);
  ASSERT_EQ(single.covariance.scalar_type(), at::kFloat);
  EXPECT_LT(row_relative_error(single.covariance, exact.covariance), 1e-4);
  EXPECT_LT(row_relative_error(single.std_per_scale, exact.std_per_scale), 1e-4);
  const auto g = gradients(single.covariance, weight, f), r = gradients(exact.covariance, weight, d);
  for (int k = 0; k < 3; ++k) EXPECT_LT(row_relative_error(g[k], r[k]), 1e-3) << k;
}

TEST(FusedCovariance, RejectsMismatchedInputs) {
  const auto in = test::random_covariance_inputs(10, 3);
  EXPECT_THROW(world_covariance_packed(in.jacobian.slice(1, 0, 2), in.quaternion, in.log_scale), c10::Error);
  EXPECT_THROW(world_covariance_packed(in.jacobian, in.quaternion.slice(0, 0, 9), in.log_scale), c10::Error);
  EXPECT_THROW(world_covariance_packed(in.jacobian, in.quaternion, in.log_scale.to(at::kFloat)), c10::Error);
}

}  // namespace
}  // namespace tega::uvd
