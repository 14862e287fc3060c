#pragma once
// MP4 output of `tega render`, through OpenCV's VideoWriter (codec mp4v)
// where the build has OpenCV (TEGA_HAVE_OPENCV) with FFmpeg or GStreamer.

#include <filesystem>
#include <string>
#include <vector>

namespace tega::tools {

// Whether this build writes videos; when not, why (for the user).
bool video_supported();
std::string video_unsupported_reason();

// Encodes the images (any format read_image reads, all of one size) as an
// MP4 at `fps`, atomically. Throws tega::Error naming the file when the
// images differ in size, the encoder refuses, or video is unsupported.
void write_video(const std::vector<std::filesystem::path>& images, const std::filesystem::path& file, double fps);

}  // namespace tega::tools
