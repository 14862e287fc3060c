#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/tools/video.h"

namespace tega::tools {

// mp4v in an MP4 container is FFmpeg's (or GStreamer's) to write. An OpenCV
// built without them (the one scripts/gpu-carry builds) still lists them
// among its writer backends, as plugins it cannot load: hasBackend asks.
bool video_supported() {
  return cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) || cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER);
}

std::string video_unsupported_reason() {
  return video_supported() ? std::string()
                           : "this OpenCV was built without FFmpeg or GStreamer, so no MP4 is written; the frames are "
                             "there as images";
}

namespace {

void encode(const std::vector<std::filesystem::path>& images, const std::filesystem::path& file,
            const std::filesystem::path& target, double fps) {
  cv::VideoWriter writer;
  int width = 0, height = 0;
  for (const auto& path : images) {
    const Image8 image = read_image_u8(path);
    if (!writer.isOpened()) {
      width = image.width;
      height = image.height;
      if (!writer.open(target.string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps, cv::Size(width, height)))
        throw Error(file, "OpenCV's VideoWriter cannot encode mp4v here");
    }
    if (image.width != width || image.height != height) throw Error(path, "differs in size from the video's first image");
    cv::Mat bgr(height, width, CV_8UC3);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        auto& pixel = bgr.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) pixel[2 - c] = image.at(x, y, std::min(c, image.channels - 1));
      }
    writer.write(bgr);
  }
  writer.release();
}

}  // namespace

void write_video(const std::vector<std::filesystem::path>& images, const std::filesystem::path& file, double fps) {
  if (images.empty()) throw Error(file, "a video needs at least one image");
  write_file_atomic(file, [&](const std::filesystem::path& temp) {
    // OpenCV picks the container from the extension, so it encodes into a
    // name that keeps it, moved onto the temporary afterwards.
    const std::filesystem::path named = temp.string() + file.extension().string();
    try {
      encode(images, file, named, fps);
    } catch (...) {
      std::filesystem::remove(named);
      throw;
    }
    std::filesystem::rename(named, temp);
  });
}

}  // namespace tega::tools
