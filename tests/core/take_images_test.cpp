// A take's images made RGB by its pixel format: raw Bayer mosaics demosaiced
// at full and half size, against the colour image they were sampled from.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "tega/core/downsample.h"
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

const struct {
  std::string format, quad;
} kPatterns[] = {{"BayerRG8", "RGGB"}, {"BayerBG8", "BGGR"}, {"BayerGB8", "GBRG"}, {"BayerGR8", "GRBG"}};

TEST(Debayer, HalfSizeIsTheColourAtEachQuadsCentre) {
  for (const auto& p : kPatterns) {
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

// GenICam names a mosaic by its first row, OpenCV by its second: each of the
// four patterns must come out as the colour it sampled.
TEST(Debayer, FullSizeIsTheColourAtEveryPixelForEveryPattern) {
  for (const auto& p : kPatterns) {
    const Image8 rgb = debayer(mosaic(p.quad, 64, 48), p.format);
    ASSERT_EQ(rgb.channels, 3);
    int worst = 0;
    for (int y = 2; y < rgb.height - 2; ++y)
      for (int x = 2; x < rgb.width - 2; ++x)
        for (int c = 0; c < 3; ++c)
          worst = std::max(worst, int(std::abs(rgb.at(x, y, c) - ramp(c, x, y)) + 0.5));
    EXPECT_LE(worst, 2) << p.format;
  }
}

TEST(Debayer, GreyIsTheLumaOfTheColourForEveryPattern) {
  for (const auto& p : kPatterns) {
    const Image8 grey = debayer_grey(mosaic(p.quad, 64, 48), p.format);
    ASSERT_EQ(grey.channels, 1);
    int worst = 0;
    for (int y = 2; y < grey.height - 2; ++y)
      for (int x = 2; x < grey.width - 2; ++x) {
        const double luma = 0.299 * ramp(0, x, y) + 0.587 * ramp(1, x, y) + 0.114 * ramp(2, x, y);
        worst = std::max(worst, int(std::abs(grey.at(x, y, 0) - luma) + 0.5));
      }
    EXPECT_LE(worst, 2) << p.format;
  }
}

// Capture stores 16-bit mosaics (Bayer*12 and *16) demosaiced the same way.
TEST(Debayer, SixteenBitMosaicsDemosaicAsEightBitOnes) {
  const Image8 raw = mosaic("GRBG", 32, 24);
  std::vector<uint16_t> raw16(raw.pixels.size()), rgb16(raw.pixels.size() * 3);
  for (size_t i = 0; i < raw.pixels.size(); ++i) raw16[i] = uint16_t(raw.pixels[i] * 256);
  demosaic(raw16.data(), raw.width, raw.height, 2, "BayerGR16", rgb16.data());
  const Image8 rgb = debayer(raw, "BayerGR8");
  int worst = 0;
  for (size_t i = 0; i < rgb16.size(); ++i) worst = std::max(worst, std::abs(int(rgb16[i]) - 256 * rgb.pixels[i]));
  EXPECT_LE(worst, 256);
}

TEST(TakeImages, RecordedImagesBecomeRgbByThePixelFormat) {
  Image8 colour(4, 2, 3), grey(4, 2, 1);
  for (size_t i = 0; i < colour.pixels.size(); ++i) colour.pixels[i] = uint8_t(10 * i);
  for (size_t i = 0; i < grey.pixels.size(); ++i) grey.pixels[i] = uint8_t(30 * i);
  EXPECT_EQ(recorded_rgb(colour, "RGB8", "a.png").pixels, colour.pixels);
  const Image8 swapped = recorded_rgb(colour, "BGR8", "a.png");
  EXPECT_EQ(swapped.at(1, 1, 0), colour.at(1, 1, 2));
  EXPECT_EQ(swapped.at(1, 1, 2), colour.at(1, 1, 0));
  const Image8 mono = recorded_rgb(grey, "Mono8", "a.png");
  EXPECT_EQ(mono.at(2, 1, 1), grey.at(2, 1, 0));
  // An even factor demosaics a raw mosaic straight to half size.
  const Image8 raw = mosaic("RGGB", 64, 48);
  EXPECT_EQ(recorded_rgb(raw, "BayerRG8", "a.png", 2).pixels, debayer_half(raw, "BayerRG8").pixels);
  EXPECT_EQ(recorded_rgb(raw, "BayerRG8", "a.png", 4).pixels,
            box_downsample_dropping_remainder(debayer_half(raw, "BayerRG8"), 2).pixels);
  try {
    recorded_rgb(colour, "Mono8", "takes/t/cam00/000000.png");
    FAIL() << "a 3-channel image taken as Mono8";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cam00/000000.png"), std::string::npos) << e.what();
  }
}

TEST(Debayer, RejectsUnknownFormatsAndOddSizes) {
  EXPECT_THROW(debayer_half(Image8(8, 8, 1), "Mono8"), Error);
  EXPECT_THROW(debayer_half(Image8(8, 8, 3), "BayerRG8"), Error);
  EXPECT_THROW(debayer_half(Image8(9, 8, 1), "BayerRG8"), Error);
}

}  // namespace
}  // namespace tega
