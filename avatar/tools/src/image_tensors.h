#pragma once
// Conversions between tega images and the tensors the avatar renders
// (private to tega_tools).

#include <ATen/ATen.h>

#include <filesystem>

#include "tega/core/image.h"

namespace tega::tools::detail {

// A dataset image as uint8 RGBA [H,W,4] (RGB files get an opaque alpha).
at::Tensor read_rgba(const std::filesystem::path& file);

// Float RGB [3,H,W] (any device) -> an interleaved float image.
ImageF to_image(const at::Tensor& rgb);
// Float RGB [3,H,W] in [0,1] (any device) -> 8-bit RGB, rounded as image files store it.
Image8 to_image8(const at::Tensor& rgb);

}  // namespace tega::tools::detail
