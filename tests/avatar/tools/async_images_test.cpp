#include "async_images.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tega/core/error.h"
#include "tega/core/image.h"
#include "test_support.h"

namespace {

using namespace tega;
using namespace tega::tools::detail;
namespace fs = std::filesystem;

// A float RGB [3,H,W] ramp with values below 0 and above 1, distinct per image.
at::Tensor ramp(int index) {
  return at::linspace(-0.1, 1.1, 3 * 5 * 7, at::kFloat).reshape({3, 5, 7}).roll(index, 2);
}

uint8_t stored(float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255)); }

TEST(BackgroundImageWriter, WritesEveryImageAsGivenWhileTheCallerGoesOn) {
  const test::TempDir tmp;
  {
    BackgroundImageWriter writer(2);
    for (int i = 0; i < 9; ++i) writer.write(ramp(i), tmp.path() / ("view" + std::to_string(i) + ".png"));
    writer.finish();
  }
  for (int i = 0; i < 9; ++i) {
    const Image8 image = read_image_u8(tmp.path() / ("view" + std::to_string(i) + ".png"));
    ASSERT_EQ(image.width, 7);
    ASSERT_EQ(image.height, 5);
    ASSERT_EQ(image.channels, 3);
    const at::Tensor expected = ramp(i);
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 7; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(image.at(x, y, c), stored(expected[c][y][x].item<float>())) << i;
  }
}

TEST(BackgroundImageWriter, AFailedWriteIsRethrownToTheCaller) {
  const test::TempDir tmp;
  test::write_text(tmp / "blocker", "a file where the render's folder should be");
  BackgroundImageWriter writer(2);
  writer.write(ramp(0), tmp / "blocker" / "view.png");
  try {
    writer.finish();
    FAIL() << "a write under a regular file succeeded";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("blocker"), std::string::npos) << e.what();
  }
}

TEST(ImagePrefetcher, HandsBackTheImagesInOrderAndRethrowsAFailedRead) {
  const test::TempDir tmp;
  std::vector<fs::path> files;
  for (int i = 0; i < 6; ++i) {
    Image8 image(3, 2, i % 2 ? 3 : 4, static_cast<uint8_t>(10 * i));
    files.push_back(tmp.path() / ("image" + std::to_string(i) + ".png"));
    write_image(image, files.back());
  }
  files.push_back(tmp.path() / "missing.png");
  ImagePrefetcher images(files, 3);
  for (int i = 0; i < 6; ++i) {
    const at::Tensor rgba = images.next();
    ASSERT_EQ(rgba.sizes(), (at::IntArrayRef{2, 3, 4}));
    EXPECT_EQ(rgba[1][2][0].item<uint8_t>(), 10 * i);
    EXPECT_EQ(rgba[1][2][3].item<uint8_t>(), i % 2 ? 255 : 10 * i);  // RGB files read as opaque
  }
  const std::string message = test::error_message([&] { images.next(); });
  EXPECT_NE(message.find("missing.png"), std::string::npos) << message;
  EXPECT_THROW(images.next(), std::out_of_range);
}

}  // namespace
