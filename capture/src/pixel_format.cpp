#include "tega/capture/pixel_format.h"

#include "tega/core/error.h"

namespace tega::capture {

PixelFormatInfo pixel_format_info(const std::string& name) {
  if (name == "Mono8") return {name, 1, 8, 1, "", false};
  if (name == "Mono10" || name == "Mono12" || name == "Mono16") return {name, 1, 16, 2, "", false};
  if (name == "RGB8") return {name, 3, 8, 3, "", false};
  if (name == "BGR8") return {name, 3, 8, 3, "", true};
  for (const char* pattern : {"RG", "BG", "GB", "GR"}) {
    const std::string bayer = std::string("Bayer") + pattern;
    if (name == bayer + "8") return {name, 1, 8, 1, pattern, false};
    if (name == bayer + "10" || name == bayer + "12" || name == bayer + "16") return {name, 1, 16, 2, pattern, false};
  }
  throw Error("pixel format '" + name +
              "' cannot be recorded losslessly; use Mono8, Mono10/12/16, RGB8, BGR8 or Bayer{RG,BG,GB,GR}{8,10,12,16} "
              "(unpacked)");
}

}  // namespace tega::capture
