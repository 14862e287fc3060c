#pragma once
// Per-Gaussian math of shaded_sh (spherical_harmonics.h), shared by the CPU
// loops and the CUDA kernels: the shading multiplier s > 0 folded into the SH
// coefficients, S·max(c, 0) = max(S·c, 0) with
//   dc' = s·dc + ½(s − 1)/C0,  rest' = s·rest.
// Backward: ∂dc = s·∂dc',  ∂rest = s·∂rest',  ∂s = Σ ∂dc'·(dc + ½/C0) + Σ ∂rest'·rest.

#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::trainer::shading_fold {

// Element k < 3·used of one Gaussian's row out [used × 3], from its dc [3]
// and rest [stored × 3], of which the first used − 1 coefficients count.
template <typename T>
TEGA_HD T forward_element(const T* dc, const T* rest, T s, T half_over_c0, int k) {
  return k < 3 ? s * dc[k] + half_over_c0 * (s - T(1)) : s * rest[k - 3];
}

// Gradients of one row from grad_out [used × 3]: grad_dc [3], grad_rest
// [stored × 3] (zero past the used coefficients), and ∂s as the return value.
template <typename T>
TEGA_HD T backward_row(const T* dc, const T* rest, T s, T half_over_c0, int used, int stored, const T* grad_out,
                       T* grad_dc, T* grad_rest) {
  T grad_s = T(0);
  for (int c = 0; c < 3; ++c) {
    grad_dc[c] = s * grad_out[c];
    grad_s += grad_out[c] * (dc[c] + half_over_c0);
  }
  for (int k = 3; k < 3 * used; ++k) {
    grad_rest[k - 3] = s * grad_out[k];
    grad_s += grad_out[k] * rest[k - 3];
  }
  for (int k = 3 * (used - 1); k < 3 * stored; ++k) grad_rest[k] = T(0);
  return grad_s;
}

}  // namespace tega::trainer::shading_fold
