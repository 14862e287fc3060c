#pragma once
// Between tega's RGB images and OpenCV's BGR matrices, for drawing.

#include <opencv2/core.hpp>

#include "tega/core/image.h"

namespace tega::report {

Image8 image_of(const cv::Mat& bgr);  // 8-bit BGR -> RGB
cv::Mat bgr_of(const Image8& image);  // grey, RGB or RGBA (alpha dropped) -> 8-bit BGR

}  // namespace tega::report
