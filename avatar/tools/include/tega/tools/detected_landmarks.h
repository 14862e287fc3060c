#pragma once
// The paper's landmark error (TeGA §5, Table 1), `landmark_px` of `tega eval`
// (docs/render-eval-export.md#landmarks): a 68-point landmark detector runs
// on the render and on the ground truth, both in the same face box, and the
// error is the mean pixel distance between the two detections over the 68
// points. The box is the one tracking's predictors are trained with
// (grown_landmark_box): the bounding box of the tracked mesh's 68 landmark
// vertices projected into the view, grown by 7.5 % of its size on each side.
// The same box for both images means that only what the detector reads from
// the pixels moves the points.

#include <ATen/ATen.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "tega/core/image.h"

namespace tega::tools {

// The 68 landmarks (pixels, the markup's order) of the face in the box of an 8-bit RGB image.
using LandmarkPredictor = std::function<std::vector<Eigen::Vector2d>(const Image8&, const Eigen::AlignedBox2d&)>;

// A dlib 68-point shape predictor (.dat; the landmarks library's LandmarkDetector).
// Throws tega::Error naming the file when it is not one, and in a build
// without dlib (the tracking/ folder's tega_landmarks) saying so.
LandmarkPredictor load_landmark_predictor(const std::filesystem::path& file);

// The detector's box from the 68 projected landmarks; nullopt when one is behind the camera.
std::optional<Eigen::AlignedBox2d> landmark_detection_box(const std::vector<std::optional<Eigen::Vector2d>>& landmarks);

// Mean distance (pixels) between the landmarks `predictor` finds on the two
// float RGB images [3,H,W] in [0,1] (any device; quantised to 8 bits as an
// image file would be) in `box`.
double detected_landmark_error_px(const LandmarkPredictor& predictor, const at::Tensor& render,
                                  const at::Tensor& truth, const Eigen::AlignedBox2d& box);

}  // namespace tega::tools
