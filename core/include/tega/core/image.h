#pragma once
// Images: interleaved channels, row-major, top row first.
// Where the build has OpenImageIO (TEGA_HAVE_OPENIMAGEIO) it reads and writes
// every format (PNG, JPEG, TIFF, EXR, ...). Without it (the GPU machine) PNG
// (8/16-bit, grey, grey+alpha, RGB, RGBA) goes through libpng and the other
// formats throw a tega::Error saying so. Colour values are never
// premultiplied by alpha. See docs/meshes-and-images.md.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace tega {

template <typename T>
struct ImageBuffer {
  int width = 0, height = 0, channels = 0;
  std::vector<T> pixels;  // width * height * channels

  ImageBuffer() = default;
  ImageBuffer(int w, int h, int c, T fill = T{})
      : width(w), height(h), channels(c), pixels(static_cast<size_t>(w) * h * c, fill) {}
  T& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
  const T& at(int x, int y, int c) const {
    return pixels[(static_cast<size_t>(y) * width + x) * channels + c];
  }
  bool empty() const { return pixels.empty(); }
};

using Image8 = ImageBuffer<uint8_t>;
using Image16 = ImageBuffer<uint16_t>;
using ImageF = ImageBuffer<float>;  // [0, 1] for 8/16-bit sources; as stored for float files

// Storage depth when writing. Auto: float for EXR, 8-bit otherwise.
enum class BitDepth { Auto, U8, U16, F32 };

// Throws tega::Error naming the file when it is missing or not a readable image.
ImageF read_image(const std::filesystem::path& file);
Image8 read_image_u8(const std::filesystem::path& file);  // 16-bit and float sources are rounded
// Atomic (temp file + rename). Float values are clamped to [0, 1] and rounded
// when stored as integers; PNG cannot store F32.
void write_image(const ImageF& image, const std::filesystem::path& file, BitDepth depth = BitDepth::Auto);
void write_image(const Image8& image, const std::filesystem::path& file);
void write_image(const Image16& image, const std::filesystem::path& file);

// Whether this build can read/write the format of `file` (by extension).
bool image_format_supported(const std::filesystem::path& file);

// The libpng path alone, whatever the build has. It is the only PNG path
// without OpenImageIO; callable directly so that every build tests it.
ImageF read_png_with_libpng(const std::filesystem::path& file);
void write_png_with_libpng(const Image8& image, const std::filesystem::path& file);   // atomic
void write_png_with_libpng(const Image16& image, const std::filesystem::path& file);  // atomic

// Pixels another owner holds, e.g. a camera's buffer: rows `row_bytes` apart,
// 8-bit or native-endian 16-bit samples, 1-4 channels.
struct PixelView {
  const void* data = nullptr;
  int width = 0, height = 0, channels = 0, bit_depth = 8;
  size_t row_bytes = 0;
};
// A PNG straight from the view, without a copy, at zlib level `compression`
// (0-9). Level 1 is the capture writer's: several times faster than the
// default for files about 10% larger. Atomic; errors name `file` and the cause.
void write_png_view(const PixelView& view, const std::filesystem::path& file, int compression);
// The same as raw pixels in one zstd frame (`.zst`, docs/layouts.md#raw-pixels-in-zstd) at zstd
// `level` (1-19): at level 1 about PNG level 1's size, written 2-3 times and read 3-4 times faster.
// read_image_u8 and read_image_header read it.
void write_zstd_view(const PixelView& view, const std::filesystem::path& file, int level);

}  // namespace tega
