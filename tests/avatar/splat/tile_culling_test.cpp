// The ellipse-against-tile test that binning uses: it may drop a tile only
// when the blending would skip the splat at every pixel of it.

#include <tega/splat/gaussian_math.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tega::splat {
namespace {

// A splat with a random 2D covariance (low-pass included, as projection
// makes it), centred near the origin.
template <typename T>
Splat2D<T> random_splat(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double pi = std::acos(-1.0);
  const double angle = pi * unit(rng);
  const double s0 = std::exp(std::log(0.2) + unit(rng) * std::log(400.0));  // 0.2 .. 80 px
  const double s1 = s0 * std::exp(std::log(0.02) + unit(rng) * std::log(50.0));  // aspect 0.02 .. 1
  const double c = std::cos(angle), s = std::sin(angle);
  const double xx = c * c * s0 * s0 + s * s * s1 * s1 + kLowPassVariance;
  const double yy = s * s * s0 * s0 + c * c * s1 * s1 + kLowPassVariance;
  const double xy = c * s * (s0 * s0 - s1 * s1);
  const double det = xx * yy - xy * xy;
  Splat2D<T> sp{};
  sp.u = T(20.0 * (unit(rng) - 0.5));
  sp.v = T(20.0 * (unit(rng) - 0.5));
  sp.opacity = T(kMinAlpha + (0.999 - kMinAlpha) * unit(rng));
  sp.conic_a = T(yy / det);
  sp.conic_b = T(-xy / det);
  sp.conic_c = T(xx / det);
  return sp;
}

// Whether any pixel centre of [x0, x1] × [y0, y1] gets alpha ≥ kMinAlpha,
// evaluated as the blending does.
template <typename T>
bool any_pixel_blended(const Splat2D<T>& sp, int x0, int y0, int x1, int y1) {
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      T gaussian;
      if (splat_alpha(sp, T(x), T(y), gaussian) >= T(kMinAlpha)) return true;
    }
  return false;
}

template <typename T>
void check_never_drops_a_blended_tile() {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> corner(-120, 100);
  int blended = 0, culled = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Splat2D<T> sp = random_splat<T>(rng);
    const T level = splat_level(sp);
    for (int r = 0; r < 8; ++r) {
      const int x0 = corner(rng), y0 = corner(rng);
      const int x1 = x0 + kTileSize - 1, y1 = y0 + kTileSize - 1;
      const bool touched = splat_may_touch(sp, level, T(x0), T(y0), T(x1), T(y1));
      if (any_pixel_blended(sp, x0, y0, x1, y1)) {
        ++blended;
        ASSERT_TRUE(touched) << "trial " << trial << " tile at " << x0 << ", " << y0;
      } else if (!touched) {
        ++culled;
      }
    }
  }
  // Both outcomes occur often enough for the test to mean something.
  EXPECT_GT(blended, 2000);
  EXPECT_GT(culled, 10000);
}

TEST(TileCulling, NeverDropsATileWithABlendedPixelInDouble) { check_never_drops_a_blended_tile<double>(); }
TEST(TileCulling, NeverDropsATileWithABlendedPixelInFloat) { check_never_drops_a_blended_tile<float>(); }

// A long thin splat along the diagonal of its bounding box touches far fewer
// tiles than the box holds, and every tile it keeps holds a blended pixel
// or borders on one.
TEST(TileCulling, DropsTheCornersOfADiagonalSplat) {
  const ImageGeometry g = make_geometry(320, 320);
  Splat2D<double> sp{};
  sp.u = 160.0;
  sp.v = 160.0;
  sp.opacity = 0.9;
  const double long_var = 60.0 * 60.0, short_var = 1.0 + kLowPassVariance;
  const double xx = 0.5 * (long_var + short_var), xy = 0.5 * (long_var - short_var), det = xx * xx - xy * xy;
  sp.conic_a = xx / det;
  sp.conic_b = -xy / det;
  sp.conic_c = xx / det;
  const double level = splat_level(sp);
  const double extent = std::sqrt(level * xx);  // half-width of the axis-aligned box
  const int t0 = int(std::ceil(sp.u - extent)) / kTileSize, t1 = int(std::floor(sp.u + extent)) / kTileSize;
  int in_box = 0, kept = 0;
  for (int ty = t0; ty <= t1; ++ty)
    for (int tx = t0; tx <= t1; ++tx) {
      ++in_box;
      const bool touched = splat_may_touch_tile(sp, level, g, tx, ty);
      kept += touched;
      const bool blended = any_pixel_blended(sp, tx * kTileSize, ty * kTileSize, tx * kTileSize + kTileSize - 1,
                                             ty * kTileSize + kTileSize - 1);
      if (blended) EXPECT_TRUE(touched) << tx << ", " << ty;
    }
  EXPECT_GE(in_box, 100);
  EXPECT_LT(kept, in_box / 3);
}

}  // namespace
}  // namespace tega::splat
