#include "tega/mvs/masks.h"

#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"

namespace tega::mvs {
namespace {

cv::Mat wrap(const Image8& image) {
  return cv::Mat(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
}

cv::Mat disc(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

}  // namespace

std::vector<uint8_t> subject_mask(const Image8& frame, const Image8& clean_plate, const MaskOptions& options) {
  if (frame.width != clean_plate.width || frame.height != clean_plate.height || frame.channels != clean_plate.channels)
    throw Error("subject mask: the frame and the clean plate differ in size or channels");
  cv::Mat a, b, difference;
  // Sensor noise differs between the two; a small blur keeps it below the threshold.
  cv::GaussianBlur(wrap(frame), a, cv::Size(5, 5), 0);
  cv::GaussianBlur(wrap(clean_plate), b, cv::Size(5, 5), 0);
  cv::absdiff(a, b, difference);
  cv::Mat largest = difference.reshape(1, int(difference.total()));
  cv::reduce(largest, largest, 1, cv::REDUCE_MAX);
  cv::Mat mask = largest.reshape(1, frame.height) > options.threshold * 255.0;
  if (options.close_px > 0) cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, disc(options.close_px));

  // Holes (parts of the subject that happen to match the backdrop) are filled:
  // whatever the background flooded from the border cannot reach is subject.
  cv::Mat outside = cv::Mat::zeros(mask.rows + 2, mask.cols + 2, CV_8U);
  mask.copyTo(outside(cv::Rect(1, 1, mask.cols, mask.rows)));
  cv::floodFill(outside, cv::Point(0, 0), 128);
  mask = outside(cv::Rect(1, 1, mask.cols, mask.rows)) != 128;

  if (options.dilate_px > 0) cv::dilate(mask, mask, disc(options.dilate_px));
  return std::vector<uint8_t>(mask.begin<uint8_t>(), mask.end<uint8_t>());
}

}  // namespace tega::mvs
