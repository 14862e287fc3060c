// The writer alone, on frames the test builds: what it stores for each
// pixel format, and its bounded queues.
#include <gtest/gtest.h>

#include "tega/capture/take_writer.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "test_support.h"

namespace tega::capture {
namespace {

namespace fs = std::filesystem;

FrameSet one_frame_set(const std::shared_ptr<std::vector<uint8_t>>& pixels, int width, int height) {
  Frame f;
  f.width = width;
  f.height = height;
  f.pixels = pixels->data();
  f.size = pixels->size();
  f.owner = pixels;
  FrameSet set;
  set.frames.push_back(f);
  return set;
}

// A flat colour seen through an RGGB mosaic (GenICam BayerRG8: R at the top-left).
std::shared_ptr<std::vector<uint8_t>> rggb_mosaic(int width, int height, int r, int g, int b) {
  auto mosaic = std::make_shared<std::vector<uint8_t>>(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      (*mosaic)[y * width + x] = uint8_t(y % 2 == 0 ? (x % 2 == 0 ? r : g) : (x % 2 == 0 ? g : b));
  return mosaic;
}

TEST(TakeWriter, RawBayerIsStoredAsTheMosaicAndDebayeredAsItsColours) {
  test::TempDir dir;
  const auto mosaic = rggb_mosaic(16, 12, 200, 100, 50);
  {
    TakeWriter raw(dir / "raw", {{"cam", pixel_format_info("BayerRG8")}}, WriterOptions{});
    ASSERT_TRUE(raw.submit(one_frame_set(mosaic, 16, 12), 0));
    raw.finish();
    ASSERT_FALSE(raw.failed()) << raw.error();
  }
  const Image8 stored = read_image_u8(dir / "raw/cam/000000.png");
  ASSERT_EQ(stored.channels, 1);
  EXPECT_EQ(stored.pixels, *mosaic);

  WriterOptions options;
  options.debayer = true;
  std::unique_ptr<TakeWriter> debayering;
  try {
    debayering = std::make_unique<TakeWriter>(dir / "rgb", std::vector<TakeWriter::Camera>{{"cam", pixel_format_info("BayerRG8")}},
                                              options);
  } catch (const Error& e) {
    GTEST_SKIP() << e.what();  // a build without OpenCV
  }
  ASSERT_TRUE(debayering->submit(one_frame_set(mosaic, 16, 12), 0));
  debayering->finish();
  ASSERT_FALSE(debayering->failed()) << debayering->error();
  const Image8 rgb = read_image_u8(dir / "rgb/cam/000000.png");
  ASSERT_EQ(rgb.channels, 3);
  EXPECT_NEAR(rgb.at(7, 5, 0), 200, 2);
  EXPECT_NEAR(rgb.at(7, 5, 1), 100, 2);
  EXPECT_NEAR(rgb.at(7, 5, 2), 50, 2);
}

TEST(TakeWriter, BgrIsStoredAsRgbAndTiffWhereTheBuildHasIt) {
  test::TempDir dir;
  auto bgr = std::make_shared<std::vector<uint8_t>>(std::vector<uint8_t>{10, 20, 30, 40, 50, 60});
  {
    TakeWriter writer(dir / "png", {{"cam", pixel_format_info("BGR8")}}, WriterOptions{});
    ASSERT_TRUE(writer.submit(one_frame_set(bgr, 2, 1), 0));
  }
  EXPECT_EQ(read_image_u8(dir / "png/cam/000000.png").pixels, (std::vector<uint8_t>{30, 20, 10, 60, 50, 40}));

  if (!image_format_supported("x.tif")) GTEST_SKIP() << "this build writes no TIFF (no OpenImageIO)";
  WriterOptions tiff;
  tiff.format = "tiff";
  {
    TakeWriter writer(dir / "tif", {{"cam", pixel_format_info("BGR8")}}, tiff);
    ASSERT_TRUE(writer.submit(one_frame_set(bgr, 2, 1), 0));
  }
  EXPECT_EQ(read_image_u8(dir / "tif/cam/000000.tif").pixels, (std::vector<uint8_t>{30, 20, 10, 60, 50, 40}));
}

TEST(TakeWriter, AFullQueueRefusesTheWholeSetAndAShortBufferIsAnError) {
  test::TempDir dir;
  WriterOptions options;
  options.queue_depth = 2;
  options.threads = 1;
  TakeWriter writer(dir / "take", {{"cam", pixel_format_info("Mono8")}}, options);
  std::mutex gate;
  gate.lock();  // holds the writer thread inside its first write
  writer.before_write = [&](const fs::path&) { std::lock_guard wait(gate); };
  const auto pixels = std::make_shared<std::vector<uint8_t>>(8 * 8, 7);
  EXPECT_TRUE(writer.submit(one_frame_set(pixels, 8, 8), 0));
  EXPECT_TRUE(writer.submit(one_frame_set(pixels, 8, 8), 1));
  EXPECT_FALSE(writer.submit(one_frame_set(pixels, 8, 8), 2));
  EXPECT_EQ(writer.queued(0), 2);
  gate.unlock();
  writer.finish();
  EXPECT_TRUE(writer.written(0, 0));
  EXPECT_TRUE(writer.written(1, 0));
  EXPECT_FALSE(writer.written(2, 0));

  const auto short_buffer = std::make_shared<std::vector<uint8_t>>(10);
  EXPECT_TRUE(writer.submit(one_frame_set(short_buffer, 8, 8), 2));
  writer.finish();
  EXPECT_TRUE(writer.failed());
  EXPECT_NE(writer.error().find("delivered 10 bytes"), std::string::npos) << writer.error();
  EXPECT_FALSE(fs::exists(dir / "take/cam/000002.png"));
}

}  // namespace
}  // namespace tega::capture
