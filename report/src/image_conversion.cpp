#include "image_conversion.h"

#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"

namespace tega::report {

Image8 image_of(const cv::Mat& bgr) {
  Image8 image(bgr.cols, bgr.rows, 3);
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, image.pixels.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return image;
}

cv::Mat bgr_of(const Image8& image) {
  cv::Mat source(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  switch (image.channels) {
    case 1:
      cv::cvtColor(source, bgr, cv::COLOR_GRAY2BGR);
      break;
    case 2: {
      cv::Mat grey;
      cv::extractChannel(source, grey, 0);
      cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
      break;
    }
    case 3:
      cv::cvtColor(source, bgr, cv::COLOR_RGB2BGR);
      break;
    case 4:
      cv::cvtColor(source, bgr, cv::COLOR_RGBA2BGR);
      break;
    default:
      throw Error("an image of " + std::to_string(image.channels) + " channels cannot be drawn");
  }
  return bgr;
}

}  // namespace tega::report
