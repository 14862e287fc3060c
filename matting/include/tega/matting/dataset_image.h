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

// `captured` shrunk by `downsample`, still distorted: the camera the build
// mattes and resamples through. Throws tega::Error unless `downsample`
// divides its size.
Camera recorded_camera_at_dataset_size(const Camera& captured, int downsample);

// The captured colour of one camera with its matte as alpha, undistorted
// together at the dataset's size (the camera's shrunk by `downsample`), so
// that the edges line up. The photo and matte come already shrunk (area
// averaging; see read_recorded_rgb): undistorting after shrinking is a
// quarter of the work of the reverse at downsample 2, and needs no
// full-size intermediate; the two orders differ by the bilinear
// interpolation's blur at one size or the other (docs/matting.md measures
// it). Made once per camera (the maps take a second at 26 megapixels);
// rgba() is thread-safe.
class DatasetResampler {
 public:
  // Throws tega::Error unless `downsample` divides the camera's size.
  DatasetResampler(const Camera& captured, int downsample);
  // `rgb` and `matte`: as recorded (distorted), at the dataset's size.
  Image8 rgba(const Image8& rgb, const Image8& matte) const;

 private:
  int width_, height_;           // the dataset's size
  cv::Mat map_xy_, map_fraction_;  // OpenCV's fixed-point maps; empty without distortion
};

}  // namespace tega::matting
