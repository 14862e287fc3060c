#pragma once
// Raw Bayer frames (GenICam BayerRG8, BayerBG8, BayerGB8, BayerGR8) to RGB,
// through OpenCV's demosaicing: the FrameLoader's RawToRgb for studio takes.

#include <string>

#include "tega/core/image.h"

namespace tega::mvs {

Image8 debayer(const Image8& raw, const std::string& pixel_format);

// The mosaic demosaiced straight to half its size, one pixel per 2 x 2 quad:
// green is the mean of the quad's two greens, red and blue are interpolated
// (bilinearly between the four nearest samples of each) to the quad's centre,
// so that the three colours line up. A third of the cost of debayer() plus an
// area halving, for stages that keep half-size images (tega dataset build).
// Throws tega::Error for an unknown format or an odd size.
Image8 debayer_half(const Image8& raw, const std::string& pixel_format);

}  // namespace tega::mvs
