#pragma once
// `tega eval`: the paper's evaluation protocol (TeGA §5,
// docs/render-eval-export.md#eval):
//
//   reenactment = held-out (test) frames seen from the training cameras
//   novel_view  = training frames seen from the held-out (test) cameras
//   train       = training frames from training cameras (split "train" only)
//
// Every view is rendered at the dataset's resolution and compared with its
// image composited over the run's background: PSNR, SSIM and L1 on the full
// image and inside the head mask (alpha > 0.5), the detail metrics of
// metrics.h inside the mask, LPIPS when weights are given; where the dataset
// defines landmark vertices, the deformation field's landmark drift
// (landmarks.h), and with the 68-point markup the eye and mouth close-ups
// (closeups.h) and, given a landmark predictor, the detected landmark error
// (detected_landmarks.h). Results: mean ± std per split, per camera and per
// frame, and every view, as JSON, plus Markdown tables like the paper's
// Table 1.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tega/core/dataset.h"
#include "tega/tools/detected_landmarks.h"
#include "tega/tools/lpips.h"
#include "tega/trainer/trained_avatar.h"

namespace tega::tools {

// Metric names, in table order; the *_masked and closeup_* ones are inside the head mask.
const std::vector<std::string>& metric_names();

struct ViewResult {
  std::string camera, frame;
  std::map<std::string, double> metrics;  // only the metrics evaluated
};

struct SplitResult {
  std::string name;  // reenactment, novel_view or train
  std::vector<ViewResult> views;
};

struct ModelResult {
  std::string name;  // the table's row label
  std::filesystem::path run;
  int64_t iteration = 0, gaussians = 0;
  std::vector<SplitResult> splits;
};

// What each optional metric measures, or why it was skipped.
struct EvalNotes {
  std::string lpips;              // "" when evaluated
  std::string landmark_px;        // the detected landmark error
  std::string landmark_drift_px;  // the deformation field's landmark drift
  std::string closeups;
};

struct EvalView {
  std::string frame, camera;
};
struct SplitViews {
  std::string name;
  std::vector<EvalView> views;  // frame-major
};
// The views of a split: "test" gives reenactment and novel_view, "train" the
// training views; an image the dataset records as missing is no view.
// Throws tega::Error for another name or an empty split.
std::vector<SplitViews> evaluation_views(const Dataset& dataset, const std::string& split);

// Renders and scores every view of `split`. lpips and landmark_predictor may
// be null (skipped). Throws tega::Error when a predictor is given and the
// dataset's landmark_vertices are not the 68 of the markup (no face box).
std::vector<SplitResult> evaluate_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset,
                                         const std::string& split, const Lpips* lpips,
                                         const LandmarkPredictor* landmark_predictor = nullptr);

// landmark_predictor: the predictor's file, empty when none was given.
EvalNotes evaluation_notes(const Dataset& dataset, bool lpips, const std::filesystem::path& landmark_predictor);

// The JSON document: notes, and per model and split the statistics of every
// metric overall, per camera and per frame, and every view. Non-finite
// numbers (PSNR of identical images is +inf) are written as the strings
// "inf", "-inf" and "nan", which JSON numbers cannot hold.
nlohmann::json evaluation_json(const std::vector<ModelResult>& models, const EvalNotes& notes);
// Table 1's layout: a row per model, columns per split and metric (mean ± std).
std::string evaluation_markdown(const std::vector<ModelResult>& models, const EvalNotes& notes);

// Writes `json_file` and the Markdown table beside it (same name, .md), atomically.
void write_evaluation(const std::vector<ModelResult>& models, const EvalNotes& notes,
                      const std::filesystem::path& json_file);

}  // namespace tega::tools
