#pragma once
// Error measure and inputs shared by the fused ops' tests (CPU and CUDA).

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <cstdint>

namespace tega::uvd::test {

// The largest error of any row (a Gaussian) relative to the larger of that
// row's largest reference magnitude and the tensor's RMS: small Gaussians
// count as much as large ones, while a row whose entries cancel to nearly
// zero is not held to a precision that its terms never had.
inline double row_relative_error(const at::Tensor& actual, const at::Tensor& expected) {
  const auto a = actual.detach().cpu().to(at::kDouble).reshape({actual.size(0), -1});
  const auto e = expected.detach().cpu().to(at::kDouble).reshape({expected.size(0), -1});
  const auto scale = at::maximum(e.abs().amax(1), e.pow(2).mean().sqrt()).clamp_min(1e-300);
  return ((a - e).abs().amax(1) / scale).max().item<double>();
}

struct CovarianceInputs {
  at::Tensor jacobian, quaternion, log_scale;  // [N,3,3], [N,4], [N,3] double
};

// Jacobians of moderate size, non-unit quaternions, scales from e^-3 to e.
inline CovarianceInputs random_covariance_inputs(int64_t n, uint64_t seed) {
  auto g = at::detail::createCPUGenerator(seed);
  return {at::randn({n, 3, 3}, g, at::kDouble), at::randn({n, 4}, g, at::kDouble) * 2,
          at::rand({n, 3}, g, at::kDouble) * 4 - 3};
}

}  // namespace tega::uvd::test
