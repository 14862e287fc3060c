// Block-average downsampling: exact block means, and what happens where the
// factor does not divide the image.

#include "tega/core/downsample.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"

namespace tega {
namespace {

// 5 x 3, two channels: channel 0 is 10 x + y, channel 1 is 200 everywhere.
Image8 ramp() {
  Image8 image(5, 3, 2);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      image.at(x, y, 0) = static_cast<uint8_t>(10 * x + y);
      image.at(x, y, 1) = 200;
    }
  return image;
}

TEST(Downsample, BlocksAreAveragedAndRounded) {
  Image8 image(4, 2, 1);
  image.pixels = {0, 1, 10, 10, 1, 1, 30, 31};
  const Image8 half = box_downsample(image, 2);
  ASSERT_EQ(half.width, 2);
  ASSERT_EQ(half.height, 1);
  EXPECT_EQ(half.at(0, 0, 0), 1);   // 3 / 4 rounds to 1
  EXPECT_EQ(half.at(1, 0, 0), 20);  // 81 / 4 rounds to 20
}

TEST(Downsample, AFactorThatDoesNotDivideIsAnErrorUnlessTheRemainderIsDropped) {
  EXPECT_THROW(box_downsample(ramp(), 2), Error);
  const Image8 half = box_downsample_dropping_remainder(ramp(), 2);
  ASSERT_EQ(half.width, 2);
  ASSERT_EQ(half.height, 1);
  ASSERT_EQ(half.channels, 2);
  // Pixel x averages columns 2x and 2x + 1 of rows 0 and 1: 20 x + 5.5, rounded up.
  EXPECT_EQ(half.at(0, 0, 0), 6);
  EXPECT_EQ(half.at(1, 0, 0), 26);
  EXPECT_EQ(half.at(1, 0, 1), 200);
  EXPECT_EQ(box_downsample_dropping_remainder(ramp(), 1).pixels, ramp().pixels);
  EXPECT_THROW(box_downsample_dropping_remainder(ramp(), 4), Error);
}

}  // namespace
}  // namespace tega
