#include "tega/mvs/debayer.h"

#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"

namespace tega::mvs {

Image8 debayer(const Image8& raw, const std::string& pixel_format) {
  // OpenCV names a mosaic by its second row's first two pixels: GenICam's
  // BayerRG (R G / G B) is OpenCV's BayerBG.
  const std::string pattern = pixel_format.size() >= 7 ? pixel_format.substr(5, 2) : "";
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

}  // namespace tega::mvs
