#include "image_tensors.h"

#include <algorithm>

#include "tega/core/error.h"

namespace tega::tools::detail {

at::Tensor read_rgba(const std::filesystem::path& file) {
  Image8 image = read_image_u8(file);
  if (image.channels != 3 && image.channels != 4)
    throw Error(file, "has " + std::to_string(image.channels) + " channels, expected RGB or RGBA");
  at::Tensor pixels =
      at::from_blob(image.pixels.data(), {image.height, image.width, image.channels}, at::kByte).clone();
  if (image.channels == 3) pixels = at::cat({pixels, at::full({image.height, image.width, 1}, 255, at::kByte)}, 2);
  return pixels;
}

ImageF to_image(const at::Tensor& rgb) {
  const at::Tensor pixels = rgb.detach().permute({1, 2, 0}).to(at::kCPU, at::kFloat).contiguous();
  ImageF image(static_cast<int>(pixels.size(1)), static_cast<int>(pixels.size(0)), 3);
  std::copy_n(pixels.data_ptr<float>(), image.pixels.size(), image.pixels.begin());
  return image;
}

Image8 to_image8(const at::Tensor& rgb) {
  const at::Tensor pixels =
      rgb.detach().clamp(0, 1).mul(255).round().permute({1, 2, 0}).to(at::kCPU, at::kByte).contiguous();
  Image8 image(static_cast<int>(pixels.size(1)), static_cast<int>(pixels.size(0)), 3);
  std::copy_n(pixels.data_ptr<uint8_t>(), image.pixels.size(), image.pixels.begin());
  return image;
}

}  // namespace tega::tools::detail
