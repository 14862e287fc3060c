#include "tega/tools/closeups.h"

#include <algorithm>
#include <cmath>

#include "tega/core/error.h"

namespace tega::tools {

namespace {

std::vector<int> landmark_range(int first, int last) {
  std::vector<int> indices;
  for (int i = first; i <= last; ++i) indices.push_back(i);
  return indices;
}

}  // namespace

const std::vector<CloseupRegion>& closeup_regions() {
  static const std::vector<CloseupRegion> regions{
      {"eyes", {landmark_range(36, 41), landmark_range(42, 47)}},
      {"mouth", {landmark_range(48, 67)}}};
  return regions;
}

const std::vector<std::string>& closeup_metric_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const CloseupRegion& region : closeup_regions())
      for (const char* metric : {"psnr", "ssim", "hf_psnr", "gradient_error"})
        out.push_back("closeup_" + region.name + "_" + metric);
    return out;
  }();
  return names;
}

std::optional<PixelBox> closeup_box(const std::vector<Eigen::Vector2d>& points, int width, int height) {
  Eigen::Vector2d low = points.at(0), high = points.at(0);
  for (const Eigen::Vector2d& p : points) low = low.cwiseMin(p), high = high.cwiseMax(p);
  const double margin = kCloseupMargin * (high - low).maxCoeff();
  const Eigen::Vector2d centre = (low + high) / 2;
  // Half the side, so that the pixels whose centres lie in the grown box are
  // at least kCloseupMinimumSide a side.
  const Eigen::Vector2d half =
      ((high - low) / 2 + Eigen::Vector2d::Constant(margin)).cwiseMax(kCloseupMinimumSide / 2.0);
  PixelBox box{static_cast<int>(std::ceil(centre.x() - half.x())), static_cast<int>(std::ceil(centre.y() - half.y())),
               static_cast<int>(std::floor(centre.x() + half.x())) + 1,
               static_cast<int>(std::floor(centre.y() + half.y())) + 1};
  box.x0 = std::max(box.x0, 0), box.y0 = std::max(box.y0, 0);
  box.x1 = std::min(box.x1, width), box.y1 = std::min(box.y1, height);
  if (box.x0 >= box.x1 || box.y0 >= box.y1) return std::nullopt;
  return box;
}

std::vector<PixelBox> region_boxes(const CloseupRegion& region,
                                   const std::vector<std::optional<Eigen::Vector2d>>& landmarks, int width,
                                   int height) {
  if (landmarks.size() != kMarkupLandmarks)
    throw Error("close-ups need the 68 landmarks of the Multi-PIE markup, got " + std::to_string(landmarks.size()));
  std::vector<PixelBox> boxes;
  for (const std::vector<int>& part : region.parts) {
    std::vector<Eigen::Vector2d> points;
    for (int landmark : part) {
      if (!landmarks[size_t(landmark)]) return {};
      points.push_back(*landmarks[size_t(landmark)]);
    }
    const std::optional<PixelBox> box = closeup_box(points, width, height);
    if (!box) return {};
    boxes.push_back(*box);
  }
  return boxes;
}

std::map<std::string, double> closeup_metrics(const ErrorMaps& maps, const at::Tensor& head_mask,
                                              const std::vector<std::optional<Eigen::Vector2d>>& landmarks) {
  const int height = static_cast<int>(head_mask.size(0)), width = static_cast<int>(head_mask.size(1));
  std::map<std::string, double> out;
  for (const CloseupRegion& region : closeup_regions()) {
    // The boxes' union: pixels in both eye boxes (a profile view) count once.
    const at::Tensor inside = at::zeros_like(head_mask);
    for (const PixelBox& box : region_boxes(region, landmarks, width, height))
      inside.slice(0, box.y0, box.y1).slice(1, box.x0, box.x1).fill_(true);
    const MaskedMetrics m = masked_metrics(maps, inside.logical_and(head_mask));
    const std::string prefix = "closeup_" + region.name + "_";
    out[prefix + "psnr"] = m.psnr;
    out[prefix + "ssim"] = m.ssim;
    out[prefix + "hf_psnr"] = m.hf_psnr;
    out[prefix + "gradient_error"] = m.gradient_error;
  }
  return out;
}

}  // namespace tega::tools
