#pragma once
// Depth-map fusion's pixels on the GPU (private to tega_mvs_depth).

#include <vector>

#include "fusion_math.h"

namespace tega::mvs::detail {

// Every pixel_step-th pixel of every pixel_step-th row of every view fused on the GPU, the same
// math as the CPU path (fusion_math.h), the points in its order: view by view, row by row, left
// to right. `views` point at host memory. Throws tega::Error in a build without CUDA or without a
// usable GPU.
std::vector<FusedSample> fuse_pixels_cuda(const std::vector<FusionView>& views, const FusionParameters& parameters,
                                          int pixel_step);

}  // namespace tega::mvs::detail
