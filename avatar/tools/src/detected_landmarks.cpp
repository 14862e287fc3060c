#include "tega/tools/detected_landmarks.h"

#include "image_tensors.h"
#include "tega/core/error.h"
#include "tega/core/landmark_box.h"

namespace tega::tools {

std::optional<Eigen::AlignedBox2d> landmark_detection_box(
    const std::vector<std::optional<Eigen::Vector2d>>& landmarks) {
  Eigen::AlignedBox2d box;
  for (const std::optional<Eigen::Vector2d>& landmark : landmarks) {
    if (!landmark) return std::nullopt;
    box.extend(*landmark);
  }
  return grown_landmark_box(box);
}

double detected_landmark_error_px(const LandmarkPredictor& predictor, const at::Tensor& render,
                                  const at::Tensor& truth, const Eigen::AlignedBox2d& box) {
  const std::vector<Eigen::Vector2d> on_render = predictor(detail::to_image8(render), box),
                                     on_truth = predictor(detail::to_image8(truth), box);
  if (on_render.empty() || on_render.size() != on_truth.size())
    throw Error("the landmark predictor found " + std::to_string(on_render.size()) + " and " +
                std::to_string(on_truth.size()) + " landmarks on a render and its truth");
  double sum = 0;
  for (size_t i = 0; i < on_render.size(); ++i) sum += (on_render[i] - on_truth[i]).norm();
  return sum / static_cast<double>(on_render.size());
}

}  // namespace tega::tools
