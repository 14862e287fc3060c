#pragma once
// Per-element math of encode_positions (tega/nn/positional_encoding.h),
// shared by the CPU loops and the CUDA kernels. Feature f of one axis, at
// x = scale·c for the axis's coordinate c:
//   f = 0:       x                 d/dc = scale
//   f = 1 + 2k:  sin(ω x)          d/dc = ω scale cos(ω x),   d²/dc² = -(ω scale)² sin(ω x)
//   f = 2 + 2k:  cos(ω x)          d/dc = -ω scale sin(ω x),  d²/dc² = -(ω scale)² cos(ω x)
// with ω = π 2^k. The second derivative is what the backward pass needs for
// the gradient that reaches c through the first.

#include <cmath>

#include "tega/core/host_device.h"

namespace tega::nn::positional_encoding {

constexpr int kAxes = 3;
constexpr double kPi = 3.141592653589793;

template <typename T>
struct Feature {
  T value, first, second;  // the feature and its derivatives w.r.t. the coordinate
};

template <typename T>
TEGA_HD void sin_cos(T phase, T* s, T* c) {
#if defined(__CUDA_ARCH__)
  sincos(phase, s, c);  // CUDA's float and double overloads
#else
  *s = std::sin(phase);
  *c = std::cos(phase);
#endif
}

// Feature f of one axis at its coordinate. Each call evaluates one sine and
// cosine: the CUDA kernels compute the features of a row in the order they
// store them, not octave by octave.
template <typename T>
TEGA_HD Feature<T> encoding_feature(int f, T coordinate, T scale) {
  const T x = coordinate * scale;
  if (f == 0) return {x, scale, T(0)};
  const int k = (f - 1) / 2;
  const T omega = T(kPi) * T(int64_t(1) << k), rate = omega * scale;
  T s, c;
  sin_cos(x * omega, &s, &c);
  if ((f - 1) % 2 == 0) return {s, rate * c, -rate * rate * s};
  return {c, -rate * s, -rate * rate * c};
}

}  // namespace tega::nn::positional_encoding
