#pragma once
// From a pinhole image to the captured one: the head is rendered once
// through the lens-free camera (that image is the dataset's, which holds
// undistorted images) and the captured image is resampled from it through
// the lens distortion, as a lens would bend it. Internal to tega_synth.

#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"

namespace tega::synth {

// For every pixel of the captured (distorted) image, the point of the
// pinhole image (same K, no distortion) that the lens brings there.
struct PinholeLookup {
  int width = 0, height = 0;
  std::vector<float> x, y;  // row-major
};

PinholeLookup pinhole_lookup(const Camera& camera);

// Bilinear; points outside the pinhole image read as empty (zero).
ImageF resample_through_lens(const ImageF& pinhole, const PinholeLookup& lookup);

}  // namespace tega::synth
