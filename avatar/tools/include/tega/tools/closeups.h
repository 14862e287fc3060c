#pragma once
// Close-ups of `tega eval` (docs/render-eval-export.md#close-ups): the eyes
// and the mouth, where the paper's close-ups (TeGA §5, Figs. 6-7) show what
// whole-image metrics average away (wrinkles, blinks, stubble).
//
// A region's boxes come from the 68 landmarks of the Multi-PIE markup (the
// dataset's landmark_vertices on the tracked mesh) projected into the view:
// per part (an eye, the mouth) the bounding box of its landmarks, every side
// moved out by kCloseupMargin times the box's longer side, widened about
// its centre to at least kCloseupMinimumSide pixels a side and clipped to
// the image. The metrics are those of the head mask (metrics.h), averaged
// over the head mask's pixels inside the region's boxes, on the render at
// the dataset's resolution: nothing is resampled.

#include <ATen/ATen.h>

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tega/tools/metrics.h"

namespace tega::tools {

// The landmarks of the Multi-PIE markup (dlib's 68-point order), which the
// close-ups and the detector's face box (detected_landmarks.h) need.
constexpr size_t kMarkupLandmarks = 68;

// The eye box reaches the brow, the crow's feet and the cheek below the lid;
// the mouth box the lips' surroundings, from the nose to the chin.
constexpr double kCloseupMargin = 0.4;
// SSIM's window and the detail band are 11 px wide: a box of a low-resolution
// view's eye would hold hardly a window.
constexpr int kCloseupMinimumSide = 32;

// Pixels x0 <= x < x1, y0 <= y < y1 (pixel centres at integer coordinates).
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool operator==(const PixelBox&) const = default;
};

struct CloseupRegion {
  std::string name;                     // closeup_<name>_psnr, ...
  std::vector<std::vector<int>> parts;  // a box per part around these landmarks (0-based, 68-point markup)
};
// eyes (the subject's right eye, 36-41, and left eye, 42-47: two boxes) and mouth (48-67).
const std::vector<CloseupRegion>& closeup_regions();

// closeup_<region>_{psnr,ssim,hf_psnr,gradient_error} of every region, in table order.
const std::vector<std::string>& closeup_metric_names();

// The box around `points` (pixels) as above; nullopt when it misses the image.
std::optional<PixelBox> closeup_box(const std::vector<Eigen::Vector2d>& points, int width, int height);

// A region's boxes from the view's 68 projected landmarks (nullopt: behind
// the camera); empty when a part has a landmark behind the camera or misses
// the image. Throws tega::Error for other than 68 landmarks.
std::vector<PixelBox> region_boxes(const CloseupRegion& region,
                                   const std::vector<std::optional<Eigen::Vector2d>>& landmarks, int width, int height);

// Every close-up metric of a view from its error maps and head mask [H,W];
// NaN for a region without boxes or without head-mask pixels in them.
std::map<std::string, double> closeup_metrics(const ErrorMaps& maps, const at::Tensor& head_mask,
                                              const std::vector<std::optional<Eigen::Vector2d>>& landmarks);

}  // namespace tega::tools
