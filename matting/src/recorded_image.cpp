#include "tega/matting/recorded_image.h"

#include "tega/core/downsample.h"
#include "tega/core/error.h"
#include "tega/mvs/debayer.h"
#include "tega/mvs/frame_views.h"

namespace tega::matting {

Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height,
                         int downsample) {
  const auto file = take.image_path(camera, frame);
  const Image8 recorded = read_image_u8(file);
  if (recorded.width != width || recorded.height != height)
    throw Error(file, "is " + std::to_string(recorded.width) + "x" + std::to_string(recorded.height) + ", but camera " +
                          camera + " of the rig is " + std::to_string(width) + "x" + std::to_string(height));
  const bool raw_bayer = take.pixel_format.rfind("Bayer", 0) == 0 && recorded.channels == 1;
  if (raw_bayer && downsample % 2 == 0)
    return box_downsample_dropping_remainder(mvs::debayer_half(recorded, take.pixel_format), downsample / 2);
  return box_downsample_dropping_remainder(mvs::recorded_rgb(recorded, take, mvs::debayer, file.string()), downsample);
}

}  // namespace tega::matting
