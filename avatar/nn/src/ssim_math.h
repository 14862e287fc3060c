#pragma once
// Per-pixel math of the fused SSIM (fused_ssim.h), shared by the CPU path
// (float and double) and the CUDA kernels, so that both compute the same
// thing: plain C++17 without torch types, compiled by g++ and nvcc alike.
//
// With the window-weighted moments at a pixel (E = Gaussian blur, zero padding)
//   μa = E[a], μb = E[b], σa² = E[a²] − μa², σb² = E[b²] − μb², σab = E[ab] − μa μb,
//   m = A1 A2 / (B1 B2),  A1 = 2 μa μb + C1,  A2 = 2 σab + C2,
//                         B1 = μa² + μb² + C1, B2 = σa² + σb² + C2.
// The moments that depend on a are μa, E[a²] and E[ab], and each is a blur of
// a, a² or ab. So for the mean M of m over N pixels,
//   N ∂M/∂a = blur(∂m/∂μa) + 2 a blur(∂m/∂E[a²]) + b blur(∂m/∂E[ab]),
// where the blur is its own adjoint because the window is symmetric, and
//   ∂m/∂E[a²] = ∂m/∂σa² = −m / B2,
//   ∂m/∂E[ab] = ∂m/∂σab = 2 A1 / (B1 B2),
//   ∂m/∂μa (at fixed E[a²], E[ab], i.e. through σa² and σab too)
//             = 2 μb (A2 − A1) / (B1 B2) + 2 μa m (1/B2 − 1/B1).

#include "tega/core/host_device.h"

namespace tega::nn::ssim {

inline constexpr int kRadius = 5;
inline constexpr int kTaps = 2 * kRadius + 1;
inline constexpr double kC1 = 0.01 * 0.01;
inline constexpr double kC2 = 0.03 * 0.03;

// Tap i of the normalised 1D Gaussian, σ = 1.5: exp(−(i−5)²/4.5) / Σ. Its
// outer product is losses.cpp's 11×11 window. Literals rather than exp(), so
// that the unrolled CUDA loops see compile-time constants.
template <typename T>
TEGA_HD constexpr T window_weight(int i) {
  const int d = i < kRadius ? kRadius - i : i - kRadius;
  return d == 0   ? T(0.26601172486179436)
         : d == 1 ? T(0.2130055377112537)
         : d == 2 ? T(0.10936068950970002)
         : d == 3 ? T(0.03600077212843083)
         : d == 4 ? T(0.007598758135239185)
                  : T(0.00102838008447911);
}

// The blurred moments at one pixel.
template <typename T>
struct Moments {
  T mu_a, mu_b;  // E[a], E[b]
  T aa, bb, ab;  // E[a²], E[b²], E[ab]
};

// The SSIM map at one pixel and its partial derivatives with respect to the
// moments that depend on a (see the top of this file).
template <typename T>
struct PixelSsim {
  T value;
  T d_mu_a;  // ∂m/∂μa at fixed E[a²], E[ab]
  T d_aa;    // ∂m/∂E[a²]
  T d_ab;    // ∂m/∂E[ab]
};

// B1 and B2 are written as A1 + (μa − μb)² and A2 + (σa² + σb² − 2σab): the
// same values, but for identical images the added terms are exactly zero, so
// numerator and denominator are bitwise equal and m is exactly 1.
template <typename T>
TEGA_HD PixelSsim<T> pixel_ssim(const Moments<T>& m) {
  const T var_a = m.aa - m.mu_a * m.mu_a;
  const T var_b = m.bb - m.mu_b * m.mu_b;
  const T cov = m.ab - m.mu_a * m.mu_b;
  const T a1 = T(2) * m.mu_a * m.mu_b + T(kC1);
  const T a2 = T(2) * cov + T(kC2);
  const T mu_diff = m.mu_a - m.mu_b;
  const T b1 = a1 + mu_diff * mu_diff;
  const T b2 = a2 + (var_a + var_b - T(2) * cov);
  const T inv_b1 = T(1) / b1, inv_b2 = T(1) / b2;
  PixelSsim<T> p;
  p.value = (a1 * a2) / (b1 * b2);
  p.d_aa = -p.value * inv_b2;
  p.d_ab = T(2) * a1 * inv_b1 * inv_b2;
  p.d_mu_a = T(2) * m.mu_b * (a2 - a1) * inv_b1 * inv_b2 + T(2) * m.mu_a * p.value * (inv_b2 - inv_b1);
  return p;
}

// ∂m̄/∂a at one pixel from the blurred partial derivatives, up to the
// incoming gradient over N.
template <typename T>
TEGA_HD T input_gradient(T blurred_d_mu_a, T blurred_d_aa, T blurred_d_ab, T a, T b) {
  return blurred_d_mu_a + T(2) * a * blurred_d_aa + b * blurred_d_ab;
}

}  // namespace tega::nn::ssim
