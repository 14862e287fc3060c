// Raw Bayer mosaics demosaiced at full and half size, against the colour
// image they were sampled from.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tega/core/error.h"
#include "tega/core/take_images.h"

namespace tega {
namespace {

// A colour ramp, different along x and y for each channel, at pixel centre
// (x, y): linear, so bilinear interpolation reproduces it exactly.
double ramp(int channel, double x, double y) {
  const double gx[] = {1.1, -0.7, 0.4}, gy[] = {0.5, 0.9, -1.2}, base[] = {40, 120, 200};
  return base[channel] + gx[channel] * x + gy[channel] * y;
}

// The ramp as a camera with the given GenICam pattern records it.
Image8 mosaic(const std::string& pattern, int width, int height) {
  Image8 raw(width, height, 1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const char colour = pattern[size_t((y % 2) * 2 + x % 2)];  // pattern: the quad row by row, e.g. "RGGB"
      const int channel = colour == 'R' ? 0 : colour == 'G' ? 1 : 2;
      raw.at(x, y, 0) = uint8_t(std::lround(ramp(channel, x, y)));
    }
  }
  return raw;
}

TEST(Debayer, HalfSizeIsTheColourAtEachQuadsCentre) {
  const struct {
    std::string format, quad;
  } patterns[] = {{"BayerRG8", "RGGB"}, {"BayerBG8", "BGGR"}, {"BayerGB8", "GBRG"}, {"BayerGR8", "GRBG"}};
  for (const auto& p : patterns) {
    const Image8 raw = mosaic(p.quad, 64, 48);
    const Image8 half = debayer_half(raw, p.format);
    ASSERT_EQ(half.width, 32);
    ASSERT_EQ(half.height, 24);
    ASSERT_EQ(half.channels, 3);
    int worst = 0;
    // Away from the border, where interpolation clamps.
    for (int y = 1; y < half.height - 1; ++y)
      for (int x = 1; x < half.width - 1; ++x)
        for (int c = 0; c < 3; ++c) {
          const double truth = ramp(c, 2 * x + 0.5, 2 * y + 0.5);
          worst = std::max(worst, int(std::abs(half.at(x, y, c) - truth) + 0.5));
        }
    // One grey level from the mosaic's rounding, one from the interpolation's.
    EXPECT_LE(worst, 2) << p.format;
  }
}

TEST(Debayer, HalfSizeAgreesWithFullSizeHalved) {
  const Image8 raw = mosaic("RGGB", 64, 48);
  const Image8 full = debayer(raw, "BayerRG8"), half = debayer_half(raw, "BayerRG8");
  int worst = 0;
  for (int y = 2; y < half.height - 2; ++y)
    for (int x = 2; x < half.width - 2; ++x)
      for (int c = 0; c < 3; ++c) {
        const int quad_mean = (full.at(2 * x, 2 * y, c) + full.at(2 * x + 1, 2 * y, c) + full.at(2 * x, 2 * y + 1, c) +
                               full.at(2 * x + 1, 2 * y + 1, c) + 2) / 4;
        worst = std::max(worst, std::abs(quad_mean - half.at(x, y, c)));
      }
  EXPECT_LE(worst, 2);
}

TEST(Debayer, RejectsUnknownFormatsAndOddSizes) {
  EXPECT_THROW(debayer_half(Image8(8, 8, 1), "Mono8"), Error);
  EXPECT_THROW(debayer_half(Image8(8, 8, 3), "BayerRG8"), Error);
  EXPECT_THROW(debayer_half(Image8(9, 8, 1), "BayerRG8"), Error);
}

}  // namespace
}  // namespace tega
