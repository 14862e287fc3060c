#pragma once
// Size and channel count of a PNG (or of tega's raw pixels in zstd, `.zst`)
// without decoding it: dataset validation checks thousands of images before
// training starts.

#include <filesystem>

namespace tega {

struct ImageHeader {
  int width = 0, height = 0, channels = 0, bit_depth = 0;
};

// Throws tega::Error naming the file when it is missing or not a PNG (`.zst`:
// not tega's zstd image).
ImageHeader read_image_header(const std::filesystem::path& png_file);

}  // namespace tega
