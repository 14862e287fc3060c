#include "dataset_image.h"

#include <string>

#include "tega/core/downsample.h"
#include "tega/core/error.h"
#include "tega/core/undistort.h"

namespace tega::matting {
namespace fs = std::filesystem;

void check_matte(const fs::path& file, const ImageHeader& header, int width, int height) {
  if (header.channels != 1 || header.bit_depth != 8)
    throw Error(file, "has " + std::to_string(header.channels) + " channel(s) of " + std::to_string(header.bit_depth) +
                          " bits; a matte is 8-bit grey");
  if (header.width != width || header.height != height)
    throw Error(file, "is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                          "; the captured image it mattes is " + std::to_string(width) + "x" + std::to_string(height));
}

Image8 read_matte(const fs::path& file, int width, int height, const std::string& what) {
  if (!fs::exists(file)) throw Error(file, "is missing (the matte of " + what + "; run tega matte)");
  const Image8 matte = read_image_u8(file);
  check_matte(file, {matte.width, matte.height, matte.channels, 8}, width, height);
  return matte;
}

Image8 dataset_rgba(const Image8& rgb, const Image8& matte, const UndistortionMaps* maps, int downsample) {
  Image8 rgba(rgb.width, rgb.height, 4);
  const size_t pixels = static_cast<size_t>(rgb.width) * rgb.height;
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) rgba.pixels[4 * i + c] = rgb.pixels[3 * i + c];
    rgba.pixels[4 * i + 3] = matte.pixels[i];
  }
  return maps ? undistort_image(rgba, *maps, downsample) : box_downsample(rgba, downsample);
}

}  // namespace tega::matting
