#include "preview.h"

#include <algorithm>
#include <cmath>

#include "tega/core/image.h"

namespace tega::capture {

namespace {
constexpr int kTileWidth = 320;

// The 8-bit value of the sample at (x, y), channel c; Bayer mosaics show as grey.
uint8_t sample(const Frame& f, const PixelFormatInfo& format, int x, int y, int c) {
  const size_t pixel = size_t(y) * f.width + x;
  if (format.bits == 16) {
    const auto* p = reinterpret_cast<const uint16_t*>(f.pixels);
    return uint8_t(p[pixel * format.channels + c] >> 8);
  }
  const int channel = format.bgr ? 2 - c : c;
  return f.pixels[pixel * format.channels + (format.channels == 3 ? channel : 0)];
}
}  // namespace

void write_contact_sheet(const FrameSet& set, const std::vector<PixelFormatInfo>& formats,
                         const std::filesystem::path& file) {
  const int n = int(set.frames.size());
  int source_w = 0, source_h = 0;
  for (const auto& f : set.frames)
    if (f) source_w = std::max(source_w, f->width), source_h = std::max(source_h, f->height);
  if (n == 0 || source_w == 0) return;
  const int step = std::max(1, (source_w + kTileWidth - 1) / kTileWidth);
  const int tile_w = source_w / step, tile_h = source_h / step;
  const int columns = int(std::ceil(std::sqrt(double(n))));
  const int rows = (n + columns - 1) / columns;
  Image8 sheet(columns * tile_w, rows * tile_h, 3);
  for (int i = 0; i < n; ++i) {
    const auto& f = set.frames[i];
    if (!f || f->size < size_t(f->width) * f->height * formats[i].bytes_per_pixel) continue;
    const int x0 = (i % columns) * tile_w, y0 = (i / columns) * tile_h;
    for (int y = 0; y < std::min(tile_h, f->height / step); ++y)
      for (int x = 0; x < std::min(tile_w, f->width / step); ++x)
        for (int c = 0; c < 3; ++c)
          sheet.at(x0 + x, y0 + y, c) = sample(*f, formats[i], x * step, y * step, formats[i].channels == 3 ? c : 0);
  }
  write_image(sheet, file);
}

}  // namespace tega::capture
