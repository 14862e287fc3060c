#pragma once
// One element of an Adam step, shared by the CPU loop and the CUDA kernel
// (plain C++17: nvcc compiles it with __host__ __device__).

#include <cmath>

#include "tega/core/host_device.h"

namespace tega::trainer::adam_update {

// 1 - beta is given rather than computed in T: in float, 1 - 0.999f is off
// by 1.3e-5 relative.
template <typename T>
struct Constants {
  T beta1, one_minus_beta1, beta2, one_minus_beta2, epsilon;
  T step_size;        // learning rate / (1 - beta1^t)
  T inv_correction2;  // 1 / (1 - beta2^t)
};

template <typename T, typename S>
Constants<T> constants_as(const Constants<S>& c) {
  return {T(c.beta1), T(c.one_minus_beta1), T(c.beta2), T(c.one_minus_beta2), T(c.epsilon), T(c.step_size),
          T(c.inv_correction2)};
}

TEGA_HD float square_root(float x) { return sqrtf(x); }
TEGA_HD double square_root(double x) { return sqrt(x); }

// m and v move towards g and g²; p steps by step_size · scale · m̂ / (√v̂ + ε).
template <typename T>
TEGA_HD void step_element(T& p, T g, T& m, T& v, T scale, const Constants<T>& c) {
  m = c.beta1 * m + c.one_minus_beta1 * g;
  v = c.beta2 * v + c.one_minus_beta2 * g * g;
  p -= c.step_size * scale * m / (square_root(v * c.inv_correction2) + c.epsilon);
}

}  // namespace tega::trainer::adam_update
