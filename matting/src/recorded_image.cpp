#include "tega/matting/recorded_image.h"

#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"
#include "tega/mvs/debayer.h"
#include "tega/mvs/frame_views.h"

namespace tega::matting {

Image8 area_downsampled(const Image8& image, int factor) {
  if (factor == 1) return image;
  Image8 out(image.width / factor, image.height / factor, image.channels);
  const cv::Mat in(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat target(out.height, out.width, CV_8UC(out.channels), out.pixels.data());
  cv::resize(in, target, target.size(), 0, 0, cv::INTER_AREA);
  return out;
}

Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height,
                         int downsample) {
  const auto file = take.image_path(camera, frame);
  const Image8 recorded = read_image_u8(file);
  if (recorded.width != width || recorded.height != height)
    throw Error(file, "is " + std::to_string(recorded.width) + "x" + std::to_string(recorded.height) + ", but camera " +
                          camera + " of the rig is " + std::to_string(width) + "x" + std::to_string(height));
  const bool raw_bayer = take.pixel_format.rfind("Bayer", 0) == 0 && recorded.channels == 1;
  if (raw_bayer && downsample % 2 == 0)
    return area_downsampled(mvs::debayer_half(recorded, take.pixel_format), downsample / 2);
  return area_downsampled(mvs::recorded_rgb(recorded, take, mvs::debayer, file.string()), downsample);
}

}  // namespace tega::matting
