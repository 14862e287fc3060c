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

// The fused kernels against the composed bfloat16 path (cuBLAS products and
// SiLU kernels) on the same GPU, for the deformation field's shape, the
// shading field's (one output, no Jacobian) and a field without a condition,
// on a point count that leaves a partial tile.
struct FusedCase {
  const char* name;
  int64_t condition_channels, outputs;
  bool jacobian;
};

TEST(FieldMLPCuda, FusedKernelsMatchTheComposedPath) {
  if (!torch::cuda::is_available()) GTEST_SKIP() << "no CUDA device";
  const at::TensorOptions cuda = at::TensorOptions().device(at::kCUDA, 0).dtype(at::kFloat);
  for (const FusedCase& c : {FusedCase{"deformation", 64, 3, true}, FusedCase{"shading", 64, 1, false},
                             FusedCase{"unconditioned", 0, 3, true}}) {
    SCOPED_TRACE(c.name);
    FieldMLPOptions options;
    options.condition_channels = c.condition_channels;
    options.outputs = c.outputs;
    FieldMLP fused(options);
    options.fused = false;
    FieldMLP composed(options);
    {
      at::NoGradGuard no_grad;
      fused->named_parameters()["output.weight"].normal_(0.0, 0.3);
      fused->named_parameters()["output.bias"].normal_(0.0, 0.3);
      const auto source = fused->parameters(), target = composed->parameters();
      for (size_t i = 0; i < source.size(); ++i) target[i].copy_(source[i]);
    }
    fused->to(at::Device(at::kCUDA, 0));
    composed->to(at::Device(at::kCUDA, 0));

    const int64_t n = 50021;
    at::Tensor uvd_in = at::rand({n, 3}, cuda);
    uvd_in.select(1, 2).mul_(0.25).sub_(0.05);
    const at::Tensor condition_in =
        c.condition_channels ? at::randn({n, c.condition_channels}, cuda) : at::Tensor();
    const at::Tensor value_weight = at::randn({n, c.outputs}, cuda), jacobian_weight = at::randn({n, c.outputs, 3}, cuda);

    const auto run = [&](FieldMLP& mlp, bool expect_fused) {
      const at::Tensor uvd = uvd_in.clone().requires_grad_(true);
      const at::Tensor condition = condition_in.defined() ? condition_in.clone().requires_grad_(true) : at::Tensor();
      const EncodedPositions encoded = mlp->encode(uvd, c.jacobian);
      EXPECT_EQ(mlp->runs_fused(encoded), expect_fused);
      at::Tensor loss;
      std::vector<at::Tensor> outputs;
      if (c.jacobian) {
        const FieldWithJacobian out = mlp->forward_with_jacobian(encoded, condition);
        loss = (out.value * value_weight).sum() + (out.jacobian * jacobian_weight).sum();
        outputs = {out.value.detach(), out.jacobian.detach()};
      } else {
        const at::Tensor value = mlp->forward(encoded, condition);
        loss = (value * value_weight).sum();
        outputs = {value.detach()};
      }
      std::vector<at::Tensor> inputs = mlp->parameters();
      inputs.push_back(uvd);
      if (condition.defined()) inputs.push_back(condition);
      for (const at::Tensor& g : torch::autograd::grad({loss}, inputs)) outputs.push_back(g);
      return outputs;
    };
    const std::vector<at::Tensor> expected = run(composed, false), actual = run(fused, true);
    ASSERT_EQ(actual.size(), expected.size());
    for (size_t i = 0; i < actual.size(); ++i) {
      EXPECT_EQ(actual[i].scalar_type(), at::kFloat) << "output " << i;
      EXPECT_TRUE(actual[i].isfinite().all().item<bool>()) << "output " << i;
      EXPECT_LE(relative_error(actual[i], expected[i]), 2e-2) << "output " << i;
    }
  }
}

}  // namespace
}  // namespace tega::nn
