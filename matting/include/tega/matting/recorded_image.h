#pragma once
// A take's image as the camera recorded it (distorted), made 8-bit RGB
// whatever the take's pixel format (raw Bayer is demosaiced).

#include <string>

#include "tega/core/image.h"
#include "tega/core/take.h"

namespace tega::matting {

// The image at 1/downsample of the camera's size (area-averaged; a raw Bayer
// mosaic is demosaiced straight to half size, so that the full-size RGB is
// never made). Throws tega::Error naming the file when it is missing,
// unreadable, not width x height, or does not fit the take's pixel format.
Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height,
                         int downsample = 1);

}  // namespace tega::matting
