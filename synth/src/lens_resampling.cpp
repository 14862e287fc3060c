#include "lens_resampling.h"

#include <cmath>

namespace tega::synth {

PinholeLookup pinhole_lookup(const Camera& camera) {
  PinholeLookup l;
  l.width = camera.width;
  l.height = camera.height;
  l.x.resize(size_t(l.width) * l.height);
  l.y.resize(l.x.size());
  const Eigen::Matrix3d K_inv = camera.K.inverse();
  for (int v = 0; v < l.height; ++v) {
    for (int u = 0; u < l.width; ++u) {
      const Eigen::Vector3d d = K_inv * Eigen::Vector3d(u, v, 1);
      const Eigen::Vector2d n = camera.undistort(d.head<2>() / d.z());
      const Eigen::Vector3d p = camera.K * Eigen::Vector3d(n.x(), n.y(), 1);
      l.x[size_t(v) * l.width + u] = float(p.x() / p.z());
      l.y[size_t(v) * l.width + u] = float(p.y() / p.z());
    }
  }
  return l;
}

ImageF resample_through_lens(const ImageF& pinhole, const PinholeLookup& lookup) {
  ImageF out(lookup.width, lookup.height, pinhole.channels, 0.0f);
  const auto texel = [&](int x, int y, int c) {
    return x < 0 || y < 0 || x >= pinhole.width || y >= pinhole.height ? 0.0f : pinhole.at(x, y, c);
  };
  for (int v = 0; v < lookup.height; ++v) {
    for (int u = 0; u < lookup.width; ++u) {
      const float x = lookup.x[size_t(v) * lookup.width + u], y = lookup.y[size_t(v) * lookup.width + u];
      const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
      if (x0 < -1 || y0 < -1 || x0 >= pinhole.width || y0 >= pinhole.height) continue;
      const float fx = x - x0, fy = y - y0;
      for (int c = 0; c < pinhole.channels; ++c)
        out.at(u, v, c) = (texel(x0, y0, c) * (1 - fx) + texel(x0 + 1, y0, c) * fx) * (1 - fy) +
                          (texel(x0, y0 + 1, c) * (1 - fx) + texel(x0 + 1, y0 + 1, c) * fx) * fy;
    }
  }
  return out;
}

}  // namespace tega::synth
