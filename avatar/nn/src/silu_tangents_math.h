#pragma once
// Per-element math of silu_with_tangents (tega/nn/silu_tangents.h), shared by
// the CPU loops and the CUDA kernels. With s = σ(x):
//   silu(x)   = x s
//   silu'(x)  = s (1 + x (1 - s))
//   silu''(x) = s (1 - s) (2 + x (1 - 2 s))
// Forward:  h = silu(x),  u_a = silu'(x) t_a           (a = the three uvd axes)
// Backward: ∂L/∂x = ∂L/∂h silu'(x) + silu''(x) Σ_a ∂L/∂u_a t_a,  ∂L/∂t_a = ∂L/∂u_a silu'(x)

#include <cmath>

#include "tega/core/host_device.h"

namespace tega::nn::silu_tangents {

constexpr int kAxes = 3;

template <typename T>
TEGA_HD T sigmoid(T x) {
#if defined(__CUDA_ARCH__)
  return T(1) / (T(1) + exp(-x));  // CUDA's float and double overloads
#else
  return T(1) / (T(1) + std::exp(-x));
#endif
}

// x = pre[j]; t = tangents[a * stride + j] for the three axes.
template <typename T>
TEGA_HD void forward_element(T x, const T* t, int64_t stride, T* h, T* u) {
  const T s = sigmoid(x);
  const T d1 = s * (T(1) + x * (T(1) - s));
  *h = x * s;
  for (int a = 0; a < kAxes; ++a) u[a * stride] = d1 * t[a * stride];
}

// grad_h may be null (no gradient reached the activation).
template <typename T>
TEGA_HD void backward_element(T x, const T* t, const T* grad_h, const T* grad_u, int64_t stride, T* grad_x,
                              T* grad_t) {
  const T s = sigmoid(x);
  const T d1 = s * (T(1) + x * (T(1) - s));
  const T d2 = s * (T(1) - s) * (T(2) + x * (T(1) - T(2) * s));
  T dot = T(0);
  for (int a = 0; a < kAxes; ++a) {
    dot += grad_u[a * stride] * t[a * stride];
    grad_t[a * stride] = grad_u[a * stride] * d1;
  }
  *grad_x = (grad_h ? *grad_h * d1 : T(0)) + d2 * dot;
}

}  // namespace tega::nn::silu_tangents
