#include "tega/core/take_images.h"

#include <algorithm>

#ifdef TEGA_HAVE_OPENCV
#include <opencv2/imgproc.hpp>
#endif

#include "tega/core/downsample.h"
#include "tega/core/error.h"

namespace tega {
namespace {

// GenICam's names give the first row's first two pixels: Bayer<first><second>8.
std::string pattern_of(const std::string& pixel_format) {
  return pixel_format.size() >= 7 && pixel_format.rfind("Bayer", 0) == 0 ? pixel_format.substr(5, 2) : "";
}

#ifdef TEGA_HAVE_OPENCV
// OpenCV names a mosaic by its second row's first two pixels: GenICam's
// BayerRG (R G / G B) is OpenCV's BayerBG. `to_grey`: one grey channel
// instead of RGB.
int opencv_code(const std::string& pixel_format, bool to_grey) {
  const std::string pattern = pattern_of(pixel_format);
  if (pattern == "RG") return to_grey ? cv::COLOR_BayerBG2GRAY : cv::COLOR_BayerBG2RGB;
  if (pattern == "BG") return to_grey ? cv::COLOR_BayerRG2GRAY : cv::COLOR_BayerRG2RGB;
  if (pattern == "GB") return to_grey ? cv::COLOR_BayerGR2GRAY : cv::COLOR_BayerGR2RGB;
  if (pattern == "GR") return to_grey ? cv::COLOR_BayerGB2GRAY : cv::COLOR_BayerGB2RGB;
  throw Error("debayer: unknown raw format " + pixel_format);
}
#endif

Error needs_opencv() { return Error("demosaicing a raw Bayer image needs a build with OpenCV"); }

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

bool is_bayer(const std::string& pixel_format) { return pixel_format.rfind("Bayer", 0) == 0; }

bool demosaicing_available() {
#ifdef TEGA_HAVE_OPENCV
  return true;
#else
  return false;
#endif
}

void demosaic(const void* mosaic, int width, int height, int bytes_per_sample, const std::string& pixel_format,
              void* rgb) {
#ifdef TEGA_HAVE_OPENCV
  const int code = opencv_code(pixel_format, false);
  const cv::Mat in(height, width, bytes_per_sample == 2 ? CV_16UC1 : CV_8UC1, const_cast<void*>(mosaic));
  cv::Mat out(height, width, bytes_per_sample == 2 ? CV_16UC3 : CV_8UC3, rgb);
  cv::demosaicing(in, out, code);
#else
  (void)mosaic, (void)width, (void)height, (void)bytes_per_sample, (void)pixel_format, (void)rgb;
  throw needs_opencv();
#endif
}

Image8 debayer(const Image8& raw, const std::string& pixel_format) {
  if (pattern_of(pixel_format).empty() || raw.channels != 1) throw Error("debayer: unknown raw format " + pixel_format);
  Image8 rgb(raw.width, raw.height, 3);
  demosaic(raw.pixels.data(), raw.width, raw.height, 1, pixel_format, rgb.pixels.data());
  return rgb;
}

Image8 debayer_grey(const Image8& raw, const std::string& pixel_format) {
  if (pattern_of(pixel_format).empty() || raw.channels != 1) throw Error("debayer: unknown raw format " + pixel_format);
#ifdef TEGA_HAVE_OPENCV
  const cv::Mat in(raw.height, raw.width, CV_8UC1, const_cast<uint8_t*>(raw.pixels.data()));
  Image8 grey(raw.width, raw.height, 1);
  cv::Mat out(raw.height, raw.width, CV_8UC1, grey.pixels.data());
  cv::cvtColor(in, out, opencv_code(pixel_format, true));
  return grey;
#else
  throw needs_opencv();
#endif
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

Image8 rgb_of(const Image8& image) {
  if (image.channels == 3) return image;
  Image8 rgb(image.width, image.height, 3);
  const bool grey = image.channels < 3;
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i)
    for (int c = 0; c < 3; ++c) rgb.pixels[3 * i + c] = image.pixels[image.channels * i + (grey ? 0 : c)];
  return rgb;
}

ImageF grey_of(const Image8& image) {
  ImageF grey(image.width, image.height, 1);
  for (size_t i = 0; i < grey.pixels.size(); ++i) {
    const uint8_t* p = &image.pixels[i * image.channels];
    grey.pixels[i] = image.channels >= 3 ? (0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2]) / 255.0f : p[0] / 255.0f;
  }
  return grey;
}

Image8 recorded_rgb(const Image8& recorded, const std::string& format, const std::filesystem::path& file,
                    int downsample) {
  if (is_bayer(format) && recorded.channels == 1) {
    if (downsample % 2 == 0) return box_downsample_dropping_remainder(debayer_half(recorded, format), downsample / 2);
    return box_downsample_dropping_remainder(debayer(recorded, format), downsample);
  }
  Image8 rgb;
  if (format.rfind("RGB", 0) == 0 && recorded.channels >= 3) {
    rgb = rgb_of(recorded);
  } else if (format.rfind("BGR", 0) == 0 && recorded.channels == 3) {
    rgb = recorded;
    for (size_t i = 0; i < rgb.pixels.size(); i += 3) std::swap(rgb.pixels[i], rgb.pixels[i + 2]);
  } else if (format.rfind("Mono", 0) == 0 && recorded.channels == 1) {
    rgb = rgb_of(recorded);
  } else {
    throw Error(file, "has " + std::to_string(recorded.channels) +
                          " channel(s), which does not fit the take's pixel format " + format);
  }
  return box_downsample_dropping_remainder(rgb, downsample);
}

Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int downsample) {
  const auto file = take.image_path(camera, frame);
  return recorded_rgb(read_image_u8(file), take.pixel_format, file, downsample);
}

Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height,
                         int downsample) {
  const auto file = take.image_path(camera, frame);
  const Image8 recorded = read_image_u8(file);
  if (recorded.width != width || recorded.height != height)
    throw Error(file, "is " + std::to_string(recorded.width) + "x" + std::to_string(recorded.height) + ", but camera " +
                          camera + " of the rig is " + std::to_string(width) + "x" + std::to_string(height));
  return recorded_rgb(recorded, take.pixel_format, file, downsample);
}

}  // namespace tega
