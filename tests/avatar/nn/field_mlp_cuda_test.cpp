// FieldMLP's bfloat16 layers on CUDA against the same weights in float64 on
// the CPU: value, Jacobian and the gradients that training takes from them;
// skips where there is no GPU.
#include "tega/nn/field_mlp.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/cuda.h>

#include <string>
#include <vector>
#include "../tensor_compare.h"

namespace tega::nn {
namespace {

using test::relative_error;

struct Evaluation {
  at::Tensor value, jacobian, value_only;
  std::vector<at::Tensor> gradients;  // parameters in named order, then uvd, then condition
};

// A random linear functional of value and Jacobian stands for the training
// loss, so its gradients mix every output entry.
Evaluation evaluate(FieldMLP& mlp, const at::Tensor& uvd_in, const at::Tensor& condition_in,
                    const at::Tensor& value_weight, const at::Tensor& jacobian_weight, const at::TensorOptions& to) {
  const at::Tensor uvd = uvd_in.detach().to(to).requires_grad_(true);
  const at::Tensor condition = condition_in.detach().to(to).requires_grad_(true);
  const FieldWithJacobian out = mlp->forward_with_jacobian(uvd, condition);
  const at::Tensor loss = (out.value * value_weight.to(to)).sum() + (out.jacobian * jacobian_weight.to(to)).sum();
  std::vector<at::Tensor> inputs = mlp->parameters();
  inputs.push_back(uvd);
  inputs.push_back(condition);
  Evaluation e{out.value.detach(), out.jacobian.detach(), mlp->forward(uvd, condition).detach(), {}};
  for (const at::Tensor& g : torch::autograd::grad({loss}, inputs)) e.gradients.push_back(g);
  return e;
}

TEST(FieldMLPCuda, Bfloat16LayersMatchFloat64OnTheCpu) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  FieldMLPOptions options;  // the trainer's widths: 64 hidden, 64 latent channels
  options.precision = MlpPrecision::kBFloat16;
  FieldMLP gpu(options), reference(options);
  {
    at::NoGradGuard no_grad;
    // A trained-looking field: the output layer starts at zero.
    gpu->named_parameters()["output.weight"].normal_(0.0, 0.3);
    gpu->named_parameters()["output.bias"].normal_(0.0, 0.3);
    const auto source = gpu->parameters(), target = reference->parameters();
    for (size_t i = 0; i < source.size(); ++i) target[i].copy_(source[i]);
  }
  reference->to(at::kDouble);
  gpu->to(at::Device(at::kCUDA, 0));

  const int64_t n = 20000;
  at::Tensor uvd = at::rand({n, 3}, at::kDouble);
  uvd.select(1, 2).mul_(0.25).sub_(0.05);
  const at::Tensor condition = at::randn({n, options.condition_channels}, at::kDouble);
  const at::Tensor value_weight = at::randn({n, 3}, at::kDouble), jacobian_weight = at::randn({n, 3, 3}, at::kDouble);

  const Evaluation expected =
      evaluate(reference, uvd, condition, value_weight, jacobian_weight, at::TensorOptions().dtype(at::kDouble));
  const Evaluation actual = evaluate(gpu, uvd, condition, value_weight, jacobian_weight,
                                     at::TensorOptions().device(at::kCUDA, 0).dtype(at::kFloat));
  EXPECT_EQ(actual.value.scalar_type(), at::kFloat);
  EXPECT_EQ(actual.jacobian.scalar_type(), at::kFloat);
  EXPECT_EQ(actual.value_only.scalar_type(), at::kFloat);
  EXPECT_LE(relative_error(actual.value, expected.value), 2e-2);
  EXPECT_LE(relative_error(actual.value_only, expected.value), 2e-2);
  EXPECT_LE(relative_error(actual.jacobian, expected.jacobian), 2e-2);

  std::vector<std::string> names = gpu->named_parameters().keys();
  names.push_back("uvd");
  names.push_back("condition");
  ASSERT_EQ(actual.gradients.size(), names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(actual.gradients[i].scalar_type(), at::kFloat) << names[i];
    EXPECT_LE(relative_error(actual.gradients[i], expected.gradients[i]), 2e-2) << names[i];
  }
}

}  // namespace
}  // namespace tega::nn
