#include "tega/core/downsample.h"

#include <algorithm>
#include <string>
#include <vector>

#include "tega/core/error.h"

namespace tega {

Image8 box_downsample(const Image8& image, int factor) {
  if (factor < 1 || image.width % factor != 0 || image.height % factor != 0) {
    throw Error("downsample " + std::to_string(factor) + " does not divide the image size " +
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  return box_downsample_dropping_remainder(image, factor);
}

Image8 box_downsample_dropping_remainder(const Image8& image, int factor) {
  if (factor < 1 || factor > image.width || factor > image.height)
    throw Error("downsample " + std::to_string(factor) + " does not fit the image size " +
                std::to_string(image.width) + "x" + std::to_string(image.height));
  if (factor == 1) return image;
  Image8 out(image.width / factor, image.height / factor, image.channels);
  const int channels = image.channels, area = factor * factor;
  const size_t used_row = static_cast<size_t>(out.width) * factor * channels;
  // Column sums over a block's rows first (contiguous adds, which vectorise),
  // then each block's columns: memory is read in order, which matters at 26
  // megapixels.
  std::vector<uint32_t> columns(used_row);
  for (int y = 0; y < out.height; ++y) {
    std::fill(columns.begin(), columns.end(), 0u);
    for (int dy = 0; dy < factor; ++dy) {
      const uint8_t* in = &image.at(0, y * factor + dy, 0);
      for (size_t i = 0; i < used_row; ++i) columns[i] += in[i];
    }
    uint8_t* row = &out.at(0, y, 0);
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < channels; ++c) {
        uint32_t sum = 0;
        for (int dx = 0; dx < factor; ++dx) sum += columns[(static_cast<size_t>(x) * factor + dx) * channels + c];
        row[x * channels + c] = static_cast<uint8_t>((sum + area / 2) / area);
      }
  }
  return out;
}

}  // namespace tega
