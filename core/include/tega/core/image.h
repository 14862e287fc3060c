#pragma once
// Images: interleaved channels, row-major, top row first.
// PNG (8/16-bit, grey/RGB/RGBA) is always available (libpng); JPEG, TIFF and
// EXR need OpenImageIO (built when TEGA_HAVE_OPENIMAGEIO; otherwise those
// formats throw a tega::Error saying so).

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
Image8 read_image_u8(const std::filesystem::path& file);
// Atomic (temp file + rename). Values are clamped to [0, 1] for integer formats.
void write_image(const ImageF& image, const std::filesystem::path& file, BitDepth depth = BitDepth::Auto);
void write_image(const Image8& image, const std::filesystem::path& file);
void write_image(const Image16& image, const std::filesystem::path& file);

// Whether this build can read/write the format of `file` (by extension).
bool image_format_supported(const std::filesystem::path& file);

}  // namespace tega
