#pragma once
// Per-element math of world_covariance_packed (tega/uvd/fused_covariance.h),
// shared by the CPU loops and the CUDA kernels. With q̂ = q/|q|, R = R(q̂),
// A = J R and e = exp(log_scale), all 3x3 matrices row-major:
//   M = A diag(e),  Σ = M Mᵀ (packed xx, xy, xz, yy, yz, zz),  std_k = |column k of A|
// Backward, from g = ∂L/∂(packed Σ): only the upper triangle of Σ is read, so
// ∂L/∂M = S M with S = G + Gᵀ (G upper triangular: S_ii = 2 g_ii, S_ij = g_ij);
// with P = ∂L/∂M:
//   ∂L/∂A = P diag(e),  ∂L/∂log_scale_k = Σ_i P_ik M_ik,
//   ∂L/∂J = ∂L/∂A Rᵀ,   ∂L/∂R = Jᵀ ∂L/∂A,
//   ∂L/∂q = (∂L/∂q̂ − q̂ (q̂·∂L/∂q̂)) / |q|.

#include "scalar_math.h"
#include "tega/core/host_device.h"

namespace tega::uvd::fused_covariance {

template <typename T>
struct Factors {
  T unit[4];  // q̂
  T length;   // |q|
  T r[9];     // R(q̂)
  T a[9];     // J R
  T e[3];     // exp(log_scale)
  T m[9];     // J R diag(e)
};

// The rotation of a unit quaternion (w, x, y, z), as rotation_from_quaternion (covariance.h).
template <typename T>
TEGA_HD void rotation(const T* q, T* r) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  r[0] = T(1) - T(2) * (y * y + z * z);
  r[1] = T(2) * (x * y - w * z);
  r[2] = T(2) * (x * z + w * y);
  r[3] = T(2) * (x * y + w * z);
  r[4] = T(1) - T(2) * (x * x + z * z);
  r[5] = T(2) * (y * z - w * x);
  r[6] = T(2) * (x * z - w * y);
  r[7] = T(2) * (y * z + w * x);
  r[8] = T(1) - T(2) * (x * x + y * y);
}

// ∂L/∂q̂ from ∂L/∂R (row-major) at the unit quaternion q.
template <typename T>
TEGA_HD void rotation_backward(const T* q, const T* g, T* grad_q) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  grad_q[0] = T(2) * (-z * g[1] + y * g[2] + z * g[3] - x * g[5] - y * g[6] + x * g[7]);
  grad_q[1] = T(2) * (y * g[1] + z * g[2] + y * g[3] - T(2) * x * g[4] - w * g[5] + z * g[6] + w * g[7] -
                      T(2) * x * g[8]);
  grad_q[2] = T(2) * (-T(2) * y * g[0] + x * g[1] + w * g[2] + x * g[3] + z * g[5] - w * g[6] + z * g[7] -
                      T(2) * y * g[8]);
  grad_q[3] = T(2) * (-T(2) * z * g[0] - w * g[1] + x * g[2] + w * g[3] - T(2) * z * g[4] + y * g[5] + x * g[6] +
                      y * g[7]);
}

template <typename T>
TEGA_HD void factor(const T* jacobian, const T* quaternion, const T* log_scale, Factors<T>& f) {
  f.length = math_sqrt(quaternion[0] * quaternion[0] + quaternion[1] * quaternion[1] +
                       quaternion[2] * quaternion[2] + quaternion[3] * quaternion[3]);
  TEGA_UNROLL
  for (int k = 0; k < 4; ++k) f.unit[k] = quaternion[k] / f.length;
  rotation(f.unit, f.r);
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) f.e[k] = math_exp(log_scale[k]);
  TEGA_UNROLL
  for (int i = 0; i < 3; ++i) {
    TEGA_UNROLL
    for (int j = 0; j < 3; ++j) {
      f.a[3 * i + j] = jacobian[3 * i] * f.r[j] + jacobian[3 * i + 1] * f.r[3 + j] + jacobian[3 * i + 2] * f.r[6 + j];
      f.m[3 * i + j] = f.a[3 * i + j] * f.e[j];
    }
  }
}

// Row i of a dotted with row j of b.
template <typename T>
TEGA_HD T row_dot(const T* a, int i, const T* b, int j) {
  return a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] + a[3 * i + 2] * b[3 * j + 2];
}

template <typename T>
TEGA_HD void forward_element(const T* jacobian, const T* quaternion, const T* log_scale, T* covariance,
                             T* std_per_scale) {
  Factors<T> f;
  factor(jacobian, quaternion, log_scale, f);
  covariance[0] = row_dot(f.m, 0, f.m, 0);
  covariance[1] = row_dot(f.m, 0, f.m, 1);
  covariance[2] = row_dot(f.m, 0, f.m, 2);
  covariance[3] = row_dot(f.m, 1, f.m, 1);
  covariance[4] = row_dot(f.m, 1, f.m, 2);
  covariance[5] = row_dot(f.m, 2, f.m, 2);
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k)
    std_per_scale[k] = math_sqrt(f.a[k] * f.a[k] + f.a[3 + k] * f.a[3 + k] + f.a[6 + k] * f.a[6 + k]);
}

template <typename T>
TEGA_HD void backward_element(const T* jacobian, const T* quaternion, const T* log_scale, const T* grad_covariance,
                              T* grad_jacobian, T* grad_quaternion, T* grad_log_scale) {
  Factors<T> f;
  factor(jacobian, quaternion, log_scale, f);
  const T* g = grad_covariance;
  const T s[9] = {T(2) * g[0], g[1], g[2], g[1], T(2) * g[3], g[4], g[2], g[4], T(2) * g[5]};
  T grad_a[9];
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) {
    T grad_scale = T(0);
    TEGA_UNROLL
    for (int i = 0; i < 3; ++i) {
      const T p = s[3 * i] * f.m[k] + s[3 * i + 1] * f.m[3 + k] + s[3 * i + 2] * f.m[6 + k];  // (S M)_ik
      grad_a[3 * i + k] = p * f.e[k];
      grad_scale += p * f.m[3 * i + k];
    }
    grad_log_scale[k] = grad_scale;
  }
  T grad_r[9];
  TEGA_UNROLL
  for (int i = 0; i < 3; ++i) {
    TEGA_UNROLL
    for (int j = 0; j < 3; ++j) {
      grad_jacobian[3 * i + j] = row_dot(grad_a, i, f.r, j);
      grad_r[3 * i + j] = jacobian[i] * grad_a[j] + jacobian[3 + i] * grad_a[3 + j] + jacobian[6 + i] * grad_a[6 + j];
    }
  }
  T grad_unit[4];
  rotation_backward(f.unit, grad_r, grad_unit);
  const T radial = f.unit[0] * grad_unit[0] + f.unit[1] * grad_unit[1] + f.unit[2] * grad_unit[2] +
                   f.unit[3] * grad_unit[3];
  TEGA_UNROLL
  for (int k = 0; k < 4; ++k) grad_quaternion[k] = (grad_unit[k] - f.unit[k] * radial) / f.length;
}

}  // namespace tega::uvd::fused_covariance
