#pragma once
// The GenICam pixel formats the writer stores losslessly, and how.
#include <string>

namespace tega::capture {

struct PixelFormatInfo {
  std::string name;         // GenICam name, e.g. BayerRG8
  int channels = 1;         // 3 for RGB8 / BGR8
  int bits = 8;             // bits of a stored sample: 8, or 16 (Mono10/12/16 arrive in 16-bit containers)
  int bytes_per_pixel = 1;  // in the camera's buffer
  std::string bayer;        // RG, BG, GB, GR: the top-left 2x2 of the mosaic; "" when not Bayer
  bool bgr = false;         // BGR8 is stored as RGB
};

// Throws tega::Error for a format the writer cannot store losslessly (e.g.
// the packed 12-bit formats), naming the supported ones.
PixelFormatInfo pixel_format_info(const std::string& name);

}  // namespace tega::capture
