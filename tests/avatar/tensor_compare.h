// Tensor comparisons shared by the avatar tests.
#pragma once

#include <ATen/ATen.h>

#include <algorithm>

namespace tega::test {

// ||a - reference|| / ||reference||, computed in double on the CPU whatever
// the tensors' device and type.
inline double relative_error(const at::Tensor& a, const at::Tensor& reference) {
  const at::Tensor r = reference.detach().to(at::kCPU, at::kDouble);
  return (a.detach().to(at::kCPU, at::kDouble) - r).norm().item<double>() / std::max(r.norm().item<double>(), 1e-300);
}

}  // namespace tega::test
