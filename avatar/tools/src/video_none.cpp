#include "tega/core/error.h"
#include "tega/tools/video.h"

namespace tega::tools {

bool video_supported() { return false; }

std::string video_unsupported_reason() {
  return "this build has no OpenCV (libopencv-dev), so no MP4 is written; the frames are there as images";
}

void write_video(const std::vector<std::filesystem::path>&, const std::filesystem::path& file, double) {
  throw Error(file, video_unsupported_reason());
}

}  // namespace tega::tools
