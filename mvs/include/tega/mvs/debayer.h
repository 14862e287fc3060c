#pragma once
// Raw Bayer frames (GenICam BayerRG8, BayerBG8, BayerGB8, BayerGR8) to RGB,
// through OpenCV's demosaicing: the FrameLoader's RawToRgb for studio takes.

#include <string>

#include "tega/core/image.h"

namespace tega::mvs {

Image8 debayer(const Image8& raw, const std::string& pixel_format);

}  // namespace tega::mvs
