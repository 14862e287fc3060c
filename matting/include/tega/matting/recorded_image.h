#pragma once
// A take's image as the camera recorded it (distorted), made 8-bit RGB
// whatever the take's pixel format (raw Bayer is demosaiced).

#include <string>

#include "tega/core/image.h"
#include "tega/core/take.h"

namespace tega::matting {

// Throws tega::Error naming the file when it is missing, unreadable, not
// width x height, or does not fit the take's pixel format.
Image8 read_recorded_rgb(const TakeInfo& take, const std::string& camera, int frame, int width, int height);

}  // namespace tega::matting
