#pragma once
// One image of a dataset: a captured view and its matte turned into the
// trainer's RGBA (docs/matting.md#building-the-dataset).

#include <filesystem>
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

// The captured colour with `matte` as alpha, resampled together: undistorted
// through `maps` (null: the camera has no distortion), then shrunk by
// `downsample` by block averaging. Colour and alpha go through the same
// resampling so that the edges line up.
Image8 dataset_rgba(const Image8& rgb, const Image8& matte, const UndistortionMaps* maps, int downsample);

}  // namespace tega::matting
