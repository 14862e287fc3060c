#include "tega/synth/random.h"

namespace tega::synth {

double value_noise(uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const double tx = smoothstep(0.0, 1.0, x - fx), ty = smoothstep(0.0, 1.0, y - fy);
  const double a = uniform(seed, ix, iy), b = uniform(seed, ix + 1, iy);
  const double c = uniform(seed, ix, iy + 1), d = uniform(seed, ix + 1, iy + 1);
  return (a + (b - a) * tx) * (1 - ty) + (c + (d - c) * tx) * ty;
}

}  // namespace tega::synth
