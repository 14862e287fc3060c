#pragma once
// Coarse-to-fine PatchMatch: a view at half size, and a half-size estimate
// carried up to the full size as the start of the full-size sweeps.

#include "patch_match_math.h"
#include "tega/mvs/patch_match.h"

namespace tega::mvs::detail {

// Grey image averaged over 2 x 2 pixels, the mask on where any of them is, the
// camera scaled by 0.5 (Camera::scaled's pixel centres). The colour is left out.
StereoView half_size(const StereoView& view);

// Each pixel of `fine` takes the plane of the nearest pixel of `coarse` (its
// depth where that plane meets the pixel's ray) and that pixel's cost. Pixels
// whose plane misses [depth_min, depth_max] or whose coarse pixel has no
// estimate get a random hypothesis, as PatchMatch starts (cost kMaxCost);
// pixels outside `fine`'s mask get none.
DepthMap upsampled(const DepthMap& coarse, const Camera& coarse_camera, const StereoView& fine, const Parameters& p);

}  // namespace tega::mvs::detail
