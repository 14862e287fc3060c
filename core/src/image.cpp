#include "tega/core/image.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "image_backends.h"
#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega {

namespace {

namespace fs = std::filesystem;
using detail::StoredImage;

std::string lowercase_extension(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_png(const fs::path& file) { return lowercase_extension(file) == ".png"; }
bool is_zstd(const fs::path& file) { return lowercase_extension(file) == ".zst"; }

PixelView view_of(const StoredImage& image, const fs::path& file) {
  if (const auto* u8 = std::get_if<Image8>(&image))
    return {u8->pixels.data(), u8->width, u8->height, u8->channels, 8, size_t(u8->width) * u8->channels};
  if (const auto* u16 = std::get_if<Image16>(&image))
    return {u16->pixels.data(), u16->width, u16->height, u16->channels, 16, size_t(u16->width) * u16->channels * 2};
  throw Error(file, "a .zst image holds 8 or 16-bit samples, not float");
}

constexpr int kZstdLevel = 1;  // as fast to write as PNG's level 0, as small as its level 1

#ifndef TEGA_HAVE_OPENIMAGEIO
[[noreturn]] void throw_needs_oiio(const fs::path& file) {
  throw Error(file, "this build of tega has no OpenImageIO, so it reads and writes PNG images only");
}
#endif

template <typename T>
void check_buffer(const ImageBuffer<T>& image, const fs::path& file) {
  const size_t expected = static_cast<size_t>(std::max(image.width, 0)) * std::max(image.height, 0) * image.channels;
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != expected) {
    throw Error(file, "cannot write a " + std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                          std::to_string(image.channels) + " image holding " + std::to_string(image.pixels.size()) +
                          " values");
  }
}

StoredImage read_stored(const fs::path& file) {
  if (!fs::exists(file)) throw Error(file, "does not exist");
  if (is_zstd(file)) return detail::read_zstd(file);
#ifdef TEGA_HAVE_OPENIMAGEIO
  return detail::read_oiio(file);
#else
  if (!is_png(file)) throw_needs_oiio(file);
  return detail::read_png(file);
#endif
}

void write_stored(const StoredImage& image, const fs::path& file) {
  std::visit([&](const auto& buffer) { check_buffer(buffer, file); }, image);
  if (is_zstd(file)) {
    const PixelView view = view_of(image, file);
    return write_file_atomic(file, [&](const fs::path& temp) { detail::write_zstd(view, temp, file, kZstdLevel); });
  }
#ifdef TEGA_HAVE_OPENIMAGEIO
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_oiio(image, temp, file); });
#else
  if (!is_png(file)) throw_needs_oiio(file);
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_png(image, temp, file); });
#endif
}

template <typename T>
ImageF normalized(const ImageBuffer<T>& image, float max) {
  ImageF out(image.width, image.height, image.channels);
  std::transform(image.pixels.begin(), image.pixels.end(), out.pixels.begin(),
                 [max](T v) { return static_cast<float>(v) / max; });
  return out;
}

template <typename T>
ImageBuffer<T> quantized(const ImageF& image, float max) {
  ImageBuffer<T> out(image.width, image.height, image.channels);
  std::transform(image.pixels.begin(), image.pixels.end(), out.pixels.begin(), [max](float v) {
    const float clamped = v > 0 ? (v < 1 ? v : 1) : 0;  // NaN -> 0
    return static_cast<T>(clamped * max + 0.5f);
  });
  return out;
}

ImageF to_float(StoredImage&& image) {
  if (auto* u8 = std::get_if<Image8>(&image)) return normalized(*u8, 255.0f);
  if (auto* u16 = std::get_if<Image16>(&image)) return normalized(*u16, 65535.0f);
  return std::move(std::get<ImageF>(image));
}

}  // namespace

ImageF read_image(const fs::path& file) { return to_float(read_stored(file)); }

Image8 read_image_u8(const fs::path& file) {
  StoredImage image = read_stored(file);
  if (auto* u8 = std::get_if<Image8>(&image)) return std::move(*u8);
  if (auto* u16 = std::get_if<Image16>(&image)) {
    Image8 out(u16->width, u16->height, u16->channels);
    std::transform(u16->pixels.begin(), u16->pixels.end(), out.pixels.begin(),
                   [](uint16_t v) { return static_cast<uint8_t>((uint32_t{v} * 255 + 32767) / 65535); });
    return out;
  }
  return quantized<uint8_t>(std::get<ImageF>(image), 255.0f);
}

void write_image(const ImageF& image, const fs::path& file, BitDepth depth) {
  if (depth == BitDepth::Auto) depth = lowercase_extension(file) == ".exr" ? BitDepth::F32 : BitDepth::U8;
  switch (depth) {
    case BitDepth::U8: return write_stored(quantized<uint8_t>(image, 255.0f), file);
    case BitDepth::U16: return write_stored(quantized<uint16_t>(image, 65535.0f), file);
    case BitDepth::F32:
    case BitDepth::Auto:
      if (is_png(file)) throw Error(file, "PNG cannot store float pixels (write 8 or 16 bits)");
      return write_stored(image, file);
  }
}

void write_image(const Image8& image, const fs::path& file) { write_stored(image, file); }
void write_image(const Image16& image, const fs::path& file) { write_stored(image, file); }

bool image_format_supported(const fs::path& file) {
  if (is_zstd(file)) return true;
#ifdef TEGA_HAVE_OPENIMAGEIO
  return detail::oiio_can_write(file);
#else
  return is_png(file);
#endif
}

ImageF read_png_with_libpng(const fs::path& file) {
  if (!fs::exists(file)) throw Error(file, "does not exist");
  return to_float(detail::read_png(file));
}

void write_png_with_libpng(const Image8& image, const fs::path& file) {
  check_buffer(image, file);
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_png(image, temp, file); });
}

void write_png_with_libpng(const Image16& image, const fs::path& file) {
  check_buffer(image, file);
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_png(image, temp, file); });
}

void write_png_view(const PixelView& view, const fs::path& file, int compression) {
  if (!view.data || view.width <= 0 || view.height <= 0 || view.channels < 1 || view.channels > 4 ||
      (view.bit_depth != 8 && view.bit_depth != 16) ||
      view.row_bytes < size_t(view.width) * view.channels * (view.bit_depth / 8) || compression < 0 ||
      compression > 9) {
    throw Error(file, "invalid pixel view or compression level for PNG");
  }
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_png_rows(view, temp, file, compression); });
}

void write_zstd_view(const PixelView& view, const fs::path& file, int level) {
  if (!view.data || view.width <= 0 || view.height <= 0 || view.channels < 1 || view.channels > 4 ||
      (view.bit_depth != 8 && view.bit_depth != 16) ||
      view.row_bytes < size_t(view.width) * view.channels * (view.bit_depth / 8) || level < 1 || level > 19) {
    throw Error(file, "invalid pixel view or zstd level (1-19)");
  }
  write_file_atomic(file, [&](const fs::path& temp) { detail::write_zstd(view, temp, file, level); });
}

}  // namespace tega
