#pragma once
// Per-element math of shaded_sh (spherical_harmonics.h), shared by the CPU
// loops and the CUDA kernels: the shading multiplier s > 0 folded into the SH
// coefficients, S·max(c, 0) = max(S·c, 0) with
//   dc' = s·dc + ½(s − 1)/C0,  rest' = s·rest.
// Backward: ∂dc = s·∂dc',  ∂rest = s·∂rest',  ∂s = Σ ∂dc'·(dc + ½/C0) + Σ ∂rest'·rest.
// Both go element by element, so that on the GPU neighbouring threads touch
// neighbouring addresses.

#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::trainer::shading_fold {

// Element k < 3·used of one Gaussian's row out [used × 3], from its dc [3]
// and rest [stored × 3], of which the first used − 1 coefficients count.
template <typename T>
TEGA_HD T forward_element(const T* dc, const T* rest, T s, T half_over_c0, int k) {
  return k < 3 ? s * dc[k] + half_over_c0 * (s - T(1)) : s * rest[k - 3];
}

// Element k < 3·(stored + 1) of one Gaussian's input gradient, the row
// [grad_dc (3) | grad_rest (3·stored)], written to `grad` (zero past the used
// coefficients) from grad_out [used × 3]; returns element k's term of ∂s.
template <typename T>
TEGA_HD T backward_element(const T* dc, const T* rest, T s, T half_over_c0, int used, int k, const T* grad_out,
                           T& grad) {
  if (k >= 3 * used) {
    grad = T(0);
    return T(0);
  }
  const T upstream = grad_out[k];
  grad = s * upstream;
  return upstream * (k < 3 ? dc[k] + half_over_c0 : rest[k - 3]);
}

}  // namespace tega::trainer::shading_fold
