#pragma once
// One image of a dataset: a captured view and its matte turned into the
// trainer's RGBA (docs/matting.md#building-the-dataset).

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"

namespace tega::matting {

// A matte as tega matte writes it is 8-bit grey, width x height (the captured
// image's size). Throws tega::Error naming `file` when `header` is not.
void check_matte(const std::filesystem::path& file, const ImageHeader& header, int width, int height);

// `file`, checked as above; a missing one is an error naming it and `what`
// it mattes.
Image8 read_matte(const std::filesystem::path& file, int width, int height, const std::string& what);

// The captured colour of one camera with its matte as alpha, resampled
// together so that the edges line up: undistorted, then shrunk by
// `downsample` by block averaging. The same result as core's
// undistort_image(rgba, maps, downsample) up to OpenCV's fixed-point
// interpolation (1/32 pixel, one level of rounding), several times faster:
// OpenCV's vectorised remap and area resize, a strip of rows at a time so
// that the full-size intermediate stays in cache. Made once per camera (the
// maps take a second at 26 megapixels); rgba() is thread-safe.
class DatasetResampler {
 public:
  // Throws tega::Error unless `downsample` divides the camera's size.
  DatasetResampler(const Camera& captured, int downsample);
  Image8 rgba(const Image8& rgb, const Image8& matte) const;

 private:
  int width_, height_, downsample_;
  cv::Mat map_xy_, map_fraction_;  // OpenCV's fixed-point maps; empty without distortion
};

}  // namespace tega::matting
