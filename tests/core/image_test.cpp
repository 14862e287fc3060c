#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"
#include "test_support.h"

namespace tega {
namespace {

// OpenImageIO is what brings EXR; without it only PNG is supported.
bool have_openimageio() { return image_format_supported("probe.exr"); }

// Distinct values in every channel; where there is alpha some pixels are
// fully transparent with non-zero colour, which premultiplication would lose.
template <typename T>
ImageBuffer<T> pattern(int width, int height, int channels, uint32_t max) {
  ImageBuffer<T> image(width, height, channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.at(x, y, c) = static_cast<T>((x * 7919u + y * 104729u + c * 1299709u + 0x0102u) % (max + 1));
      }
      const bool has_alpha = channels == 2 || channels == 4;
      if (has_alpha && x % 3 == 0) image.at(x, y, channels - 1) = 0;
    }
  }
  return image;
}

template <typename T>
ImageBuffer<T> from_float(const ImageF& image, float max) {
  ImageBuffer<T> out(image.width, image.height, image.channels);
  for (size_t i = 0; i < image.pixels.size(); ++i) out.pixels[i] = static_cast<T>(std::lround(image.pixels[i] * max));
  return out;
}

template <typename T>
void expect_same_image(const ImageBuffer<T>& actual, const ImageBuffer<T>& expected) {
  EXPECT_EQ(actual.width, expected.width);
  EXPECT_EQ(actual.height, expected.height);
  EXPECT_EQ(actual.channels, expected.channels);
  EXPECT_TRUE(actual.pixels == expected.pixels);
}

using test::error_message;

TEST(ImagePng, EightBitRoundTripsEveryChannelCount) {
  test::TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    SCOPED_TRACE(channels);
    const Image8 image = pattern<uint8_t>(13, 5, channels, 255);
    write_png_with_libpng(image, dir / "libpng.png");
    expect_same_image(from_float<uint8_t>(read_png_with_libpng(dir / "libpng.png"), 255), image);
    write_image(image, dir / "any.png");
    expect_same_image(read_image_u8(dir / "any.png"), image);
  }
}

TEST(ImagePng, SixteenBitRoundTripsEveryChannelCount) {
  test::TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    SCOPED_TRACE(channels);
    Image16 image = pattern<uint16_t>(11, 7, channels, 65535);
    image.at(1, 0, 0) = 65535;
    write_png_with_libpng(image, dir / "libpng.png");
    expect_same_image(from_float<uint16_t>(read_png_with_libpng(dir / "libpng.png"), 65535), image);
    write_image(image, dir / "any.png");
    expect_same_image(from_float<uint16_t>(read_image(dir / "any.png"), 65535), image);
  }
}

TEST(ImagePng, EightBitReadOfSixteenBitRounds) {
  test::TempDir dir;
  Image16 image(4, 1, 1);
  image.pixels = {0, 257 * 100, 257 * 100 + 128, 65535};
  write_image(image, dir / "deep.png");
  EXPECT_EQ(read_image_u8(dir / "deep.png").pixels, (std::vector<uint8_t>{0, 100, 100, 255}));
}

TEST(ImagePng, FloatPixelsAreClampedAndRounded) {
  test::TempDir dir;
  ImageF image(5, 1, 1);
  image.pixels = {-0.5f, 0.0f, 0.5f, 1.0f, 1.5f};
  write_image(image, dir / "auto.png");  // Auto: 8-bit
  EXPECT_EQ(read_image_u8(dir / "auto.png").pixels, (std::vector<uint8_t>{0, 0, 128, 255, 255}));
  write_image(image, dir / "deep.png", BitDepth::U16);
  EXPECT_EQ(from_float<uint16_t>(read_image(dir / "deep.png"), 65535).pixels,
            (std::vector<uint16_t>{0, 0, 32768, 65535, 65535}));
  const std::string message = error_message([&] { write_image(image, dir / "float.png", BitDepth::F32); });
  EXPECT_NE(message.find("float.png"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir / "float.png"));
}

TEST(ImagePng, PixelViewWithRowPaddingIsWrittenExactlyAtEveryLevel) {
  test::TempDir dir;
  const int width = 5, height = 3, row_bytes = 16;  // rows padded past width * 2 bytes
  std::vector<uint16_t> padded(row_bytes / 2 * height, 0xFFFF);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) padded[y * row_bytes / 2 + x] = uint16_t(1000 * y + 37 * x);
  for (int level : {0, 1, 9}) {
    const auto file = dir / ("view" + std::to_string(level) + ".png");
    write_png_view({padded.data(), width, height, 1, 16, size_t(row_bytes)}, file, level);
    const ImageF back = read_png_with_libpng(file);
    ASSERT_EQ(back.width, width);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) EXPECT_EQ(std::lround(back.at(x, y, 0) * 65535), 1000 * y + 37 * x);
  }
  EXPECT_THROW(write_png_view({padded.data(), width, height, 1, 16, 4}, dir / "short_rows.png", 1), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "short_rows.png"));
}

TEST(ImageZstd, RoundTripsEightAndSixteenBitsWithItsHeader) {
  test::TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    SCOPED_TRACE(channels);
    const Image8 image = pattern<uint8_t>(13, 5, channels, 255);
    write_image(image, dir / "eight.zst");
    expect_same_image(read_image_u8(dir / "eight.zst"), image);
    const ImageHeader header = read_image_header(dir / "eight.zst");
    EXPECT_EQ(header.width, 13);
    EXPECT_EQ(header.height, 5);
    EXPECT_EQ(header.channels, channels);
    EXPECT_EQ(header.bit_depth, 8);
    const Image16 deep = pattern<uint16_t>(11, 7, channels, 65535);
    write_image(deep, dir / "deep.zst");
    expect_same_image(from_float<uint16_t>(read_image(dir / "deep.zst"), 65535), deep);
    EXPECT_EQ(read_image_header(dir / "deep.zst").bit_depth, 16);
  }
  // A view with padded rows, as the dataset build writes it.
  const Image8 rgba = pattern<uint8_t>(6, 4, 4, 255);
  std::vector<uint8_t> padded(32 * 4, 0xAB);
  for (int y = 0; y < 4; ++y) std::copy_n(&rgba.pixels[size_t(y) * 24], 24, &padded[size_t(y) * 32]);
  write_zstd_view({padded.data(), 6, 4, 4, 8, 32}, dir / "view.zst", 3);
  expect_same_image(read_image_u8(dir / "view.zst"), rgba);
}

TEST(ImageZstd, DamagedFilesAreErrorsNamingThem) {
  test::TempDir dir;
  write_image(pattern<uint8_t>(64, 64, 4, 255), dir / "good.zst");
  std::string bytes = read_text_file(dir / "good.zst");
  test::write_text(dir / "truncated.zst", bytes.substr(0, bytes.size() / 2));
  test::write_text(dir / "not_tega.zst", "PNG or anything else, but not TEGAPIX1 pixels");
  std::string wrong_size = bytes;
  wrong_size[8] = 65;  // the header's width no longer matches the frame
  test::write_text(dir / "wrong_size.zst", wrong_size);
  for (const char* name : {"truncated.zst", "not_tega.zst", "wrong_size.zst"}) {
    const auto file = dir / name;
    const std::string message = error_message([&] { read_image_u8(file); });
    EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
  }
  EXPECT_NE(error_message([&] { read_image_header(dir / "not_tega.zst"); }).find("TEGAPIX1"), std::string::npos);
}

TEST(ImageErrors, NonImageAndMissingFilesAreNamed) {
  test::TempDir dir;
  const auto text = dir / "notes.png";
  test::write_text(text, "this is text, not a picture\n");
  for (const auto& read : std::vector<std::function<void(const std::filesystem::path&)>>{
           [](const auto& f) { read_image(f); }, [](const auto& f) { read_image_u8(f); },
           [](const auto& f) { read_png_with_libpng(f); }}) {
    for (const auto& file : {text, dir / "missing.png"}) {
      const std::string message = error_message([&] { read(file); });
      EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
    }
  }
}

TEST(ImageErrors, BadBufferIsRefusedAndNothingIsWritten) {
  test::TempDir dir;
  Image8 image(4, 4, 3);
  image.pixels.pop_back();
  EXPECT_THROW(write_image(image, dir / "short.png"), Error);
  EXPECT_THROW(write_png_with_libpng(image, dir / "short.png"), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(ImageFormats, PngAlwaysOtherFormatsWithOpenImageIO) {
  EXPECT_TRUE(image_format_supported("a/b.png"));
  EXPECT_TRUE(image_format_supported("B.PNG"));
  EXPECT_FALSE(image_format_supported("a.not-an-image-format"));
  if (have_openimageio()) {
    EXPECT_TRUE(image_format_supported("a.jpg"));
    EXPECT_TRUE(image_format_supported("a.tif"));
    return;
  }
  test::TempDir dir;
  const std::string message = error_message([&] { write_image(Image8(2, 2, 3), dir / "a.jpg"); });
  EXPECT_NE(message.find("OpenImageIO"), std::string::npos) << message;
}

TEST(ImageOiio, ExrKeepsFloatsExactly) {
  if (!have_openimageio()) GTEST_SKIP() << "this build has no OpenImageIO";
  test::TempDir dir;
  ImageF image(3, 2, 4);
  image.pixels = {0.0f, 1.0f, 3.5f, -0.25f, 1e-3f, 0.1f, 65504.5f, 1.0f / 3.0f, 2.0f, 0.75f, 0.5f, 0.0f,
                  7.0f, 8.0f, 9.0f,  10.0f,  -1e-6f, 1e6f, 0.3f,     0.6f,        0.9f, 1.2f,  1.5f, 1.8f};
  write_image(image, dir / "linear.exr");  // Auto: float
  expect_same_image(read_image(dir / "linear.exr"), image);
}

TEST(ImageOiio, TiffAndJpeg) {
  if (!have_openimageio()) GTEST_SKIP() << "this build has no OpenImageIO";
  test::TempDir dir;
  const Image16 deep = pattern<uint16_t>(9, 6, 3, 65535);
  write_image(deep, dir / "deep.tif");
  expect_same_image(from_float<uint16_t>(read_image(dir / "deep.tif"), 65535), deep);

  Image8 smooth(16, 16, 3);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 3; ++c) smooth.at(x, y, c) = static_cast<uint8_t>(40 + 6 * x + 4 * y + 20 * c);
    }
  }
  write_image(smooth, dir / "lossy.jpg");
  const Image8 jpeg = read_image_u8(dir / "lossy.jpg");
  ASSERT_EQ(jpeg.pixels.size(), smooth.pixels.size());
  for (size_t i = 0; i < jpeg.pixels.size(); ++i) EXPECT_NEAR(jpeg.pixels[i], smooth.pixels[i], 12) << i;
}

// The GPU machine reads PNGs through libpng, the workstation through
// OpenImageIO: both must see the same pixels in the same file, 16-bit byte
// order and alpha included.
TEST(ImageOiio, LibpngAndOpenImageIOAgree) {
  if (!have_openimageio()) GTEST_SKIP() << "this build has no OpenImageIO";
  test::TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    SCOPED_TRACE(channels);
    const Image8 shallow = pattern<uint8_t>(10, 3, channels, 255);
    const Image16 deep = pattern<uint16_t>(10, 3, channels, 65535);

    write_png_with_libpng(shallow, dir / "libpng8.png");
    write_png_with_libpng(deep, dir / "libpng16.png");
    expect_same_image(read_image_u8(dir / "libpng8.png"), shallow);
    expect_same_image(from_float<uint16_t>(read_image(dir / "libpng16.png"), 65535), deep);

    write_image(shallow, dir / "oiio8.png");
    write_image(deep, dir / "oiio16.png");
    expect_same_image(from_float<uint8_t>(read_png_with_libpng(dir / "oiio8.png"), 255), shallow);
    expect_same_image(from_float<uint16_t>(read_png_with_libpng(dir / "oiio16.png"), 65535), deep);
  }
}

}  // namespace
}  // namespace tega
