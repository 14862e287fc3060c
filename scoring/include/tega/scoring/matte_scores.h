#pragma once
// Mattes scored against the virtual studio's true alpha
// (ground_truth/<take>/alpha/<camera>/<frame:06d>.png, docs/virtual-studio.md).

#include <filesystem>
#include <string>

namespace tega::scoring {

struct MatteScores {
  int images = 0;
  double mean_error = 0, worst_mean_error = 0;          // mean |alpha - true| per image (0..1): mean, worst image
  double boundary_error = 0, worst_boundary_error = 0;  // same within `boundary_px` of the true edge
  double iou = 0, worst_iou = 0;                        // silhouettes (alpha >= 0.5): mean, worst image
  // Which image is worst by each measure, as <camera>/<frame file>, so that it can be looked at.
  std::string worst_mean_image, worst_boundary_image, worst_iou_image;
};

// Every matte of MATTES/<take>/ against the truth of `capture`. The true edge
// is where the true alpha crosses 0.5.
MatteScores score_mattes(const std::filesystem::path& mattes, const std::filesystem::path& capture,
                         const std::string& take, int boundary_px = 3);

}  // namespace tega::scoring
