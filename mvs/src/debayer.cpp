#include "tega/mvs/debayer.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"

namespace tega::mvs {
namespace {

// GenICam's names give the first row's first two pixels: Bayer<first><second>8.
std::string pattern_of(const std::string& pixel_format) {
  return pixel_format.size() >= 7 && pixel_format.rfind("Bayer", 0) == 0 ? pixel_format.substr(5, 2) : "";
}

// Where red lies in a 2 x 2 quad; blue lies diagonally opposite.
struct QuadSite {
  int x, y;
};

// The samples of one colour of the mosaic, at `site` in every quad,
// interpolated to the quad centres into `channel` of the half-size RGB
// `out`: the centre lies a quarter of a quad from the quad's own sample
// towards the neighbouring quads', hence the 9:3:3:1 bilinear weights.
void sample_at_quad_centres(const Image8& raw, QuadSite site, int channel, Image8& out) {
  const int qw = out.width, qh = out.height;
  const int dx = site.x == 0 ? 1 : -1, dy = site.y == 0 ? 1 : -1;
  for (int y = 0; y < qh; ++y) {
    const int ny = std::clamp(y + dy, 0, qh - 1);
    const uint8_t* row = raw.pixels.data() + size_t(2 * y + site.y) * size_t(raw.width) + site.x;
    const uint8_t* next = raw.pixels.data() + size_t(2 * ny + site.y) * size_t(raw.width) + site.x;
    uint8_t* target = out.pixels.data() + size_t(y) * size_t(qw) * 3 + channel;
    for (int x = 0; x < qw; ++x) {
      const int nx = std::clamp(x + dx, 0, qw - 1);
      target[3 * x] = uint8_t((9 * row[2 * x] + 3 * row[2 * nx] + 3 * next[2 * x] + next[2 * nx] + 8) >> 4);
    }
  }
}

}  // namespace

Image8 debayer(const Image8& raw, const std::string& pixel_format) {
  // OpenCV names a mosaic by its second row's first two pixels: GenICam's
  // BayerRG (R G / G B) is OpenCV's BayerBG.
  const std::string pattern = pattern_of(pixel_format);
  const int code = pattern == "RG"   ? cv::COLOR_BayerBG2RGB
                   : pattern == "BG" ? cv::COLOR_BayerRG2RGB
                   : pattern == "GB" ? cv::COLOR_BayerGR2RGB
                   : pattern == "GR" ? cv::COLOR_BayerGB2RGB
                                     : -1;
  if (code < 0 || raw.channels != 1) throw Error("debayer: unknown raw format " + pixel_format);
  cv::Mat in(raw.height, raw.width, CV_8UC1, const_cast<uint8_t*>(raw.pixels.data()));
  Image8 rgb(raw.width, raw.height, 3);
  cv::Mat out(raw.height, raw.width, CV_8UC3, rgb.pixels.data());
  cv::cvtColor(in, out, code);
  return rgb;
}

Image8 debayer_half(const Image8& raw, const std::string& pixel_format) {
  const std::string pattern = pattern_of(pixel_format);
  const QuadSite red = pattern == "RG"   ? QuadSite{0, 0}
                       : pattern == "BG" ? QuadSite{1, 1}
                       : pattern == "GB" ? QuadSite{0, 1}
                       : pattern == "GR" ? QuadSite{1, 0}
                                         : QuadSite{-1, -1};
  if (red.x < 0 || raw.channels != 1) throw Error("debayer: unknown raw format " + pixel_format);
  if (raw.width % 2 != 0 || raw.height % 2 != 0)
    throw Error("debayer: a " + std::to_string(raw.width) + "x" + std::to_string(raw.height) +
                " mosaic cannot be halved (odd size)");
  const QuadSite blue{1 - red.x, 1 - red.y};
  Image8 rgb(raw.width / 2, raw.height / 2, 3);
  sample_at_quad_centres(raw, red, 0, rgb);
  sample_at_quad_centres(raw, blue, 2, rgb);
  // The greens sit at the quad's other diagonal, both half a pixel from its centre.
  const size_t w = size_t(raw.width);
  for (int y = 0; y < rgb.height; ++y) {
    const uint8_t* top = raw.pixels.data() + size_t(2 * y) * w;
    const uint8_t* bottom = top + w;
    const uint8_t* first_green = (red.y == 0 ? top : bottom) + (1 - red.x);
    const uint8_t* second_green = (red.y == 0 ? bottom : top) + red.x;
    uint8_t* target = rgb.pixels.data() + size_t(y) * size_t(rgb.width) * 3 + 1;
    for (int x = 0; x < rgb.width; ++x) target[3 * x] = uint8_t((first_green[2 * x] + second_green[2 * x] + 1) >> 1);
  }
  return rgb;
}

}  // namespace tega::mvs
