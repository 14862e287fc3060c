#include "tega/nn/field_mlp.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <cmath>

namespace tega::nn {
namespace {

at::Tensor random_uvd(int64_t n, at::ScalarType type = at::kDouble) {
  at::Tensor uvd = at::rand({n, 3}, at::kDouble);
  uvd.select(1, 2).mul_(0.25).sub_(0.05);  // d in [-0.05, 0.2] m
  return uvd.to(type);
}

// A trained-looking MLP: the zero-initialised output layer randomised too.
FieldMLP random_mlp(const FieldMLPOptions& options) {
  FieldMLP mlp(options);
  mlp->to(at::kDouble);
  at::NoGradGuard no_grad;
  for (auto& p : mlp->parameters()) p.normal_(0.0, 0.4);
  return mlp;
}

// d y_i / d uvd by autograd, [N, outputs, 3].
at::Tensor autograd_jacobian(FieldMLP& mlp, const at::Tensor& uvd, const at::Tensor& condition) {
  const at::Tensor x = uvd.detach().requires_grad_(true);
  const at::Tensor y = mlp->forward(x, condition);
  std::vector<at::Tensor> rows;
  for (int64_t i = 0; i < y.size(1); ++i)
    rows.push_back(torch::autograd::grad({y.select(1, i).sum()}, {x}, {}, /*retain_graph=*/true)[0]);
  return at::stack(rows, 1);
}

TEST(PositionalEncoding, AxisDerivativesMatchAutograd) {
  const PositionalEncoding pe{4, 3.0};
  const at::Tensor uvd = random_uvd(7).requires_grad_(true);
  const at::Tensor encoded = pe.encode(uvd);
  ASSERT_EQ(encoded.sizes(), (std::vector<int64_t>{7, pe.channels()}));
  const at::Tensor analytic = pe.axis_derivatives(uvd.detach());
  ASSERT_EQ(analytic.sizes(), (std::vector<int64_t>{3, 7, pe.features()}));
  for (int64_t f = 0; f < pe.features(); ++f) {
    for (int64_t a = 0; a < 3; ++a) {
      const at::Tensor g = torch::autograd::grad({encoded.select(1, 3 * f + a).sum()}, {uvd}, {}, true)[0];  // [N,3]
      EXPECT_TRUE(at::allclose(analytic[a].select(1, f), g.select(1, a), 1e-12, 1e-12)) << "feature " << f;
      for (int64_t other = 0; other < 3; ++other) {
        if (other != a) EXPECT_EQ(g.select(1, other).abs().max().item<double>(), 0.0) << "feature " << f;
      }
    }
  }
}

TEST(PositionalEncoding, ChannelsAreFeatureMajorAxisMinor) {
  const PositionalEncoding pe{2, 3.0};
  const at::Tensor uvd = at::tensor({0.25, 0.5, 0.01}, at::kDouble).view({1, 3});
  const at::Tensor e = pe.encode(uvd).view({-1});
  const double x[3] = {0.25, 0.5, 0.03};
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(e[a].item<double>(), x[a]);
    EXPECT_NEAR(e[3 + a].item<double>(), std::sin(M_PI * x[a]), 1e-15);         // f = 1: sin, octave 0
    EXPECT_NEAR(e[6 + a].item<double>(), std::cos(M_PI * x[a]), 1e-15);         // f = 2: cos, octave 0
    EXPECT_NEAR(e[9 + a].item<double>(), std::sin(2 * M_PI * x[a]), 1e-15);     // f = 3: sin, octave 1
    EXPECT_NEAR(e[12 + a].item<double>(), std::cos(2 * M_PI * x[a]), 1e-15);    // f = 4: cos, octave 1
  }
}

TEST(FieldMLP, StartsAsANullFieldWithZeroJacobian) {
  FieldMLPOptions options;
  options.condition_channels = 8;
  FieldMLP mlp(options);
  const at::Tensor uvd = random_uvd(20, at::kFloat);
  const at::Tensor condition = at::randn({20, 8});
  const FieldWithJacobian out = mlp->forward_with_jacobian(uvd, condition);
  EXPECT_EQ(out.value.sizes(), (std::vector<int64_t>{20, 3}));
  EXPECT_EQ(out.jacobian.sizes(), (std::vector<int64_t>{20, 3, 3}));
  EXPECT_EQ(out.value.abs().max().item<float>(), 0.0f);
  EXPECT_EQ(out.jacobian.abs().max().item<float>(), 0.0f);
  // The hidden layers are not zero: only the output layer is.
  EXPECT_GT(mlp->named_parameters()["hidden.weight"].abs().sum().item<float>(), 0.0f);
}

TEST(FieldMLP, Bfloat16PrecisionLeavesTheCpuInFloat32) {
  FieldMLPOptions options;
  options.condition_channels = 8;
  options.precision = MlpPrecision::kFloat32;
  FieldMLP plain(options);
  options.precision = MlpPrecision::kBFloat16;
  FieldMLP mixed(options);
  {
    at::NoGradGuard no_grad;
    const auto source = plain->parameters(), target = mixed->parameters();
    for (auto& p : source) p.normal_(0.0, 0.4);
    for (size_t i = 0; i < source.size(); ++i) target[i].copy_(source[i]);
  }
  const at::Tensor uvd = random_uvd(20, at::kFloat), condition = at::randn({20, 8});
  const FieldWithJacobian a = plain->forward_with_jacobian(uvd, condition);
  const FieldWithJacobian b = mixed->forward_with_jacobian(uvd, condition);
  EXPECT_EQ(b.value.scalar_type(), at::kFloat);
  EXPECT_TRUE(at::equal(a.value, b.value));
  EXPECT_TRUE(at::equal(a.jacobian, b.jacobian));
  EXPECT_TRUE(at::equal(plain->forward(uvd, condition), mixed->forward(uvd, condition)));
}

TEST(FieldMLP, TangentJacobianMatchesAutogradAndFiniteDifferences) {
  FieldMLPOptions options;
  options.condition_channels = 5;
  options.hidden = 16;
  FieldMLP mlp = random_mlp(options);
  const at::Tensor uvd = random_uvd(9);
  const at::Tensor condition = at::randn({9, 5}, at::kDouble);

  const FieldWithJacobian out = mlp->forward_with_jacobian(uvd, condition);
  EXPECT_TRUE(at::allclose(out.value, mlp->forward(uvd, condition), 1e-14, 1e-14));
  EXPECT_GT(out.jacobian.abs().max().item<double>(), 1e-3);  // a non-trivial field
  EXPECT_TRUE(at::allclose(out.jacobian, autograd_jacobian(mlp, uvd, condition), 1e-10, 1e-12));

  const double h = 1e-6;
  for (int64_t axis = 0; axis < 3; ++axis) {
    at::Tensor step = at::zeros({1, 3}, at::kDouble);
    step[0][axis] = h;
    const at::Tensor fd = (mlp->forward(uvd + step, condition) - mlp->forward(uvd - step, condition)) / (2 * h);
    // Loose: the d axis carries frequencies up to 2^5·π·3 per metre, so the
    // truncation error of the difference quotient is ~1e-6 relative; the
    // autograd comparison above is the tight one.
    EXPECT_TRUE(at::allclose(out.jacobian.select(2, axis), fd, 1e-4, 1e-7))
        << "axis " << axis << ", max error " << (out.jacobian.select(2, axis) - fd).abs().max().item<double>();
  }
}

TEST(FieldMLP, JacobianWithoutConditionMatchesAutograd) {
  FieldMLPOptions options;
  options.condition_channels = 0;
  options.outputs = 1;
  FieldMLP mlp = random_mlp(options);
  const at::Tensor uvd = random_uvd(6);
  const FieldWithJacobian out = mlp->forward_with_jacobian(uvd, {});
  EXPECT_EQ(out.jacobian.sizes(), (std::vector<int64_t>{6, 1, 3}));
  EXPECT_TRUE(at::allclose(out.jacobian, autograd_jacobian(mlp, uvd, {}), 1e-10, 1e-12));
}

TEST(FieldMLP, SmoothnessGradientFlowsThroughTheJacobianToEveryLayer) {
  FieldMLPOptions options;
  options.condition_channels = 4;
  options.hidden = 8;
  FieldMLP mlp = random_mlp(options);
  const at::Tensor uvd = random_uvd(5);
  const at::Tensor condition = at::randn({5, 4}, at::kDouble);
  const auto objective = [&] { return mlp->forward_with_jacobian(uvd, condition).jacobian.square().sum(); };

  objective().backward();
  for (const auto& name : {"input.weight", "hidden.weight", "hidden.bias", "output.weight"}) {
    at::Tensor param = mlp->named_parameters()[name];
    ASSERT_TRUE(param.grad().defined()) << name;
    // Autograd through the tangent columns equals a finite difference of ‖J‖².
    const at::Tensor flat = param.view(-1);
    const int64_t index = flat.numel() / 2;
    const double analytic = param.grad().view(-1)[index].item<double>();
    const double h = 1e-6;
    double values[2];
    for (int s = 0; s < 2; ++s) {
      at::NoGradGuard no_grad;
      const double original = flat[index].item<double>();
      flat[index] = original + (s ? -h : h);
      values[s] = objective().item<double>();
      flat[index] = original;
    }
    const double numeric = (values[0] - values[1]) / (2 * h);
    EXPECT_NEAR(analytic, numeric, 1e-6 * std::max(1.0, std::abs(numeric))) << name;
    EXPECT_NE(analytic, 0.0) << name;
  }
  // The output bias shifts the field but not its slope.
  const at::Tensor bias_grad = mlp->named_parameters()["output.bias"].grad();
  EXPECT_TRUE(!bias_grad.defined() || bias_grad.abs().max().item<double>() == 0.0);
}

}  // namespace
}  // namespace tega::nn
