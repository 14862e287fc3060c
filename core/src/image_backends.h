#pragma once
// The libraries behind image.h (private to tega_core). Backends read the
// pixels as the file stores them and write to `target`, a temporary name that
// image.cpp renames onto `file` (whose name picks the format and appears in
// errors).

#include <filesystem>
#include <variant>

#include "tega/core/image.h"
#include "tega/core/image_header.h"

namespace tega::detail {

using StoredImage = std::variant<Image8, Image16, ImageF>;

StoredImage read_png(const std::filesystem::path& file);
// Image8 or Image16 only.
void write_png(const StoredImage& image, const std::filesystem::path& target, const std::filesystem::path& file);
void write_png_rows(const PixelView& view, const std::filesystem::path& target, const std::filesystem::path& file,
                    int compression);

// Raw pixels in zstd (image_zstd.cpp), any build.
StoredImage read_zstd(const std::filesystem::path& file);  // Image8 or Image16
ImageHeader read_zstd_header(const std::filesystem::path& file);
void write_zstd(const PixelView& view, const std::filesystem::path& target, const std::filesystem::path& file,
                int level);

#ifdef TEGA_HAVE_OPENIMAGEIO
StoredImage read_oiio(const std::filesystem::path& file);
void write_oiio(const StoredImage& image, const std::filesystem::path& target, const std::filesystem::path& file);
bool oiio_can_write(const std::filesystem::path& file);
#endif

}  // namespace tega::detail
