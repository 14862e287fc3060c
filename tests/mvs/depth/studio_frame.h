#pragma once
// One small virtual-studio frame for the depth tests, rendered once per test
// executable: its undistorted views (masked by the true coverage), its rig and
// the true depth of every view.

#include <filesystem>
#include <vector>

#include "tega/core/image.h"
#include "tega/mvs/patch_match.h"

namespace tega::test {

struct StudioFrame {
  std::vector<mvs::StereoView> views;
  std::vector<ImageF> true_depth;  // per view, 0 where the head does not cover the pixel
  std::vector<mvs::ViewTask> tasks;
};

// 7 cameras at 320 x 240, the procedural head's first frame of `expressions`.
const StudioFrame& studio_frame();

// Share of the estimated pixels on the head within `tolerance_m` of the truth,
// and share of the head's pixels estimated.
struct DepthAgreement {
  double within = 0, coverage = 0;
};
DepthAgreement agreement(const mvs::DepthMap& map, const ImageF& truth, double tolerance_m);

}  // namespace tega::test
