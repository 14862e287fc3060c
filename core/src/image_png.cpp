// PNG through libpng: the image path of builds without OpenImageIO.

#include <png.h>

#include <bit>
#include <cerrno>
#include <cstring>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "image_backends.h"
#include "tega/core/error.h"

namespace tega::detail {

namespace {

namespace fs = std::filesystem;

// libpng reports an error by longjmp-ing back to the setjmp of the function
// that called it. The functions holding a setjmp (decode_header, decode_rows,
// encode) own nothing with a destructor, so the jump skips no cleanup; the
// message waits here until their caller throws it.
struct PngMessage {
  char text[256] = "unknown libpng error";
};

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
  auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
  std::snprintf(m->text, sizeof m->text, "%s", message);
  png_longjmp(png, 1);
}

// Warnings (e.g. "known incorrect sRGB profile") concern metadata we ignore.
void on_warning(png_structp, png_const_charp) {}

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<FILE, FileCloser>;

struct Layout {
  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0;
};

// 16-bit samples are big-endian in the file; ours are native.
constexpr bool kSwap16 = std::endian::native == std::endian::little;

bool decode_header(png_structp png, png_infop info, FILE* fp, Layout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, fp);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  // Palettes become RGB, grey below 8 bits becomes 8-bit, tRNS becomes alpha.
  png_set_expand(png);
  if (kSwap16) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->width = png_get_image_width(png, info);
  layout->height = png_get_image_height(png, info);
  layout->channels = png_get_channels(png, info);
  layout->bit_depth = png_get_bit_depth(png, info);
  return true;
}

bool decode_rows(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

bool encode(png_structp png, png_infop info, FILE* fp, const Layout* layout, png_bytepp rows, int compression) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_compression_level(png, compression);
  // At the fastest levels adaptive filtering costs more time than it saves bytes.
  if (compression == 0 || compression == 1) png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  static constexpr int kColourTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                         PNG_COLOR_TYPE_RGB_ALPHA};
  png_init_io(png, fp);
  png_set_IHDR(png, info, layout->width, layout->height, layout->bit_depth, kColourTypes[layout->channels - 1],
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (layout->bit_depth == 16 && kSwap16) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

template <typename T>
std::vector<png_bytep> row_pointers(const ImageBuffer<T>& image) {
  std::vector<png_bytep> rows(image.height);
  for (int y = 0; y < image.height; ++y) {
    rows[y] = reinterpret_cast<png_bytep>(const_cast<T*>(&image.at(0, y, 0)));
  }
  return rows;
}

struct ReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~ReadStructs() { png_destroy_read_struct(&png, &info, nullptr); }
};

struct WriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~WriteStructs() { png_destroy_write_struct(&png, &info); }
};

}  // namespace

StoredImage read_png(const fs::path& file) {
  FilePtr fp(std::fopen(file.c_str(), "rb"));
  if (!fp) throw Error(file, fs::exists(file) ? "cannot be read" : "does not exist");
  png_byte signature[8];
  if (std::fread(signature, 1, sizeof signature, fp.get()) != sizeof signature ||
      png_sig_cmp(signature, 0, sizeof signature) != 0) {
    throw Error(file, "is not a PNG image");
  }

  PngMessage message;
  ReadStructs structs;
  structs.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &message, on_error, on_warning);
  if (structs.png) structs.info = png_create_info_struct(structs.png);
  if (!structs.info) throw Error(file, "libpng could not start");

  Layout layout;
  if (!decode_header(structs.png, structs.info, fp.get(), &layout)) {
    throw Error(file, std::string("is not a readable PNG image (") + message.text + ")");
  }
  StoredImage image;
  std::vector<png_bytep> rows;
  if (layout.bit_depth == 16) {
    auto& buffer = image.emplace<Image16>(layout.width, layout.height, layout.channels);
    rows = row_pointers(buffer);
  } else {
    auto& buffer = image.emplace<Image8>(layout.width, layout.height, layout.channels);
    rows = row_pointers(buffer);
  }
  if (!decode_rows(structs.png, rows.data())) {
    throw Error(file, std::string("is not a readable PNG image (") + message.text + ")");
  }
  return image;
}

void write_png(const StoredImage& image, const fs::path& target, const fs::path& file) {
  if (const auto* u8 = std::get_if<Image8>(&image)) {
    write_png_rows({u8->pixels.data(), u8->width, u8->height, u8->channels, 8, size_t(u8->width) * u8->channels},
                   target, file, PNG_Z_DEFAULT_COMPRESSION);
  } else if (const auto* u16 = std::get_if<Image16>(&image)) {
    write_png_rows({u16->pixels.data(), u16->width, u16->height, u16->channels, 16,
                    size_t(u16->width) * u16->channels * 2},
                   target, file, PNG_Z_DEFAULT_COMPRESSION);
  } else {
    throw Error(file, "PNG cannot store float pixels (write 8 or 16 bits)");
  }
}

void write_png_rows(const PixelView& view, const fs::path& target, const fs::path& file, int compression) {
  const Layout layout{static_cast<png_uint_32>(view.width), static_cast<png_uint_32>(view.height), view.channels,
                      view.bit_depth};
  // libpng takes non-const row pointers even when it only reads through them (writing).
  std::vector<png_bytep> rows(view.height);
  auto* first = static_cast<png_bytep>(const_cast<void*>(view.data));
  for (int y = 0; y < view.height; ++y) rows[y] = first + y * view.row_bytes;

  FilePtr fp(std::fopen(target.c_str(), "wb"));
  if (!fp) throw Error(file, std::string("cannot be written (") + std::strerror(errno) + ")");
  PngMessage message;
  WriteStructs structs;
  structs.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &message, on_error, on_warning);
  if (structs.png) structs.info = png_create_info_struct(structs.png);
  if (!structs.info) throw Error(file, "libpng could not start");
  if (!encode(structs.png, structs.info, fp.get(), &layout, rows.data(), compression)) {
    // libpng says only "Write Error"; the cause (e.g. a full disk) is in errno.
    const std::string cause = std::ferror(fp.get()) ? std::string(": ") + std::strerror(errno) : "";
    throw Error(file, std::string("could not be written as PNG (") + message.text + cause + ")");
  }
  if (std::fclose(fp.release()) != 0) throw Error(file, std::string("could not be written (") + std::strerror(errno) + ")");
}

}  // namespace tega::detail
