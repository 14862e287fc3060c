#pragma once
// Bilinear taps of sample_latent (encoders.h), shared by the CPU loops and the
// CUDA kernels: the same convention as grid_sample with align_corners=false
// and border padding. Texel (row r, column c) has its centre at
// u = (c + 0.5)/W, v = 1 - (r + 0.5)/H; outside the outermost centres the
// coordinate is clamped, and its derivative there is 0.

#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::nn::latent_sampling {

// Index: the integer type of texel indices (the CUDA backward uses int, which
// is cheaper there, for textures below 2^31 texels).
template <typename T, typename Index = int64_t>
struct Taps {
  Index texel[4];  // row-major texel indices: (y0,x0), (y0,x1), (y1,x0), (y1,x1)
  T weight[4];
  T dweight_du[4];   // ∂weight/∂u, ∂weight/∂v
  T dweight_dv[4];
};

// Pixel coordinate along one axis, clamped to [0, size-1]; `rate` is its
// derivative w.r.t. the texture coordinate (0 where clamped).
template <typename T, typename Index>
TEGA_HD void clamped_coordinate(T pixel, Index size, T scale, T& coordinate, T& rate) {
  const T high = T(size - 1);
  coordinate = pixel < T(0) ? T(0) : (pixel > high ? high : pixel);
  rate = (pixel < T(0) || pixel > high) ? T(0) : scale;
}

template <typename T, typename Index = int64_t>
TEGA_HD Taps<T, Index> taps(T u, T v, Index height, Index width) {
  T x, y, dx_du, dy_dv;
  clamped_coordinate(u * T(width) - T(0.5), width, T(width), x, dx_du);
  clamped_coordinate((T(1) - v) * T(height) - T(0.5), height, -T(height), y, dy_dv);
  const Index x0 = Index(x), y0 = Index(y);  // x, y >= 0: truncation is floor
  const Index x1 = x0 + 1 < width ? x0 + 1 : x0, y1 = y0 + 1 < height ? y0 + 1 : y0;
  const T fx = x - T(x0), fy = y - T(y0);
  Taps<T, Index> t;
  t.texel[0] = y0 * width + x0;
  t.texel[1] = y0 * width + x1;
  t.texel[2] = y1 * width + x0;
  t.texel[3] = y1 * width + x1;
  t.weight[0] = (T(1) - fx) * (T(1) - fy);
  t.weight[1] = fx * (T(1) - fy);
  t.weight[2] = (T(1) - fx) * fy;
  t.weight[3] = fx * fy;
  t.dweight_du[0] = -(T(1) - fy) * dx_du;
  t.dweight_du[1] = (T(1) - fy) * dx_du;
  t.dweight_du[2] = -fy * dx_du;
  t.dweight_du[3] = fy * dx_du;
  t.dweight_dv[0] = -(T(1) - fx) * dy_dv;
  t.dweight_dv[1] = -fx * dy_dv;
  t.dweight_dv[2] = (T(1) - fx) * dy_dv;
  t.dweight_dv[3] = fx * dy_dv;
  return t;
}

}  // namespace tega::nn::latent_sampling
