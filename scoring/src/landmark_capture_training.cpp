#include <algorithm>
#include <chrono>

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/scoring/landmark_capture_training.h"
#include "tega/scoring/studio_landmarks.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

double percentile(std::vector<double> values, double q) {
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

// Pixel distance of every known landmark of every sample from what the
// predictor finds in the sample's box.
std::vector<double> landmark_errors(const fs::path& predictor, const std::vector<landmarks::LandmarkSample>& samples) {
  const landmarks::LandmarkDetector detector(predictor);
  std::vector<double> errors;
  for (const landmarks::LandmarkSample& truth : samples) {
    const std::vector<Eigen::Vector2d> found = detector.detect(truth.image, truth.box).value();
    for (int i = 0; i < landmarks::kLandmarkCount; ++i)
      if (truth.landmarks[i].allFinite()) errors.push_back((found[i] - truth.landmarks[i]).norm());
  }
  return errors;
}

}  // namespace

LandmarkPredictorSummary train_landmark_predictor_on_captures(const std::vector<fs::path>& captures,
                                                              const LandmarkPredictorOptions& options,
                                                              const fs::path& out) {
  if (captures.empty()) throw Error(out, "cannot train a landmark predictor: no capture given");
  LandmarkPredictorSummary summary;
  std::vector<landmarks::LandmarkSample> training, held_out;
  for (size_t c = 0; c < captures.size(); ++c) {
    const fs::path model = options.model.empty() ? studio_head_model(captures[c]) : fs::path(options.model);
    std::vector<CaptureLandmarkSample> samples =
        capture_landmark_samples(captures[c], model_landmark_vertices(model), options.sampling);
    const bool last = c + 1 == captures.size();
    int trained = 0;
    for (CaptureLandmarkSample& sample : samples) {
      const bool hold_out = options.hold_out && last && sample.frame_position % 2 == 1;
      (hold_out ? held_out : training).push_back(std::move(sample.sample));
      trained += hold_out ? 0 : 1;
    }
    summary.samples_per_capture.push_back(trained);
    logging::info("%s: %d training images", captures[c].string().c_str(), trained);
  }
  if (!held_out.empty()) logging::info("%zu images of the last capture held out", held_out.size());
  logging::info("training on %zu images%s", training.size(),
                options.training.add_mirrored_samples ? " and their mirror images" : "");
  landmarks::LandmarkTrainingOptions training_options = options.training;
  training_options.print_progress = true;
  const auto start = std::chrono::steady_clock::now();
  landmarks::train_landmark_predictor(training, training_options, out);
  summary.training_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::vector<double> errors = landmark_errors(out, held_out);
  if (!errors.empty()) {
    summary.held_out_images = int(held_out.size());
    summary.held_out_landmarks = int(errors.size());
    summary.held_out_median_px = percentile(errors, 0.5);
    summary.held_out_p95_px = percentile(errors, 0.95);
  }
  return summary;
}

}  // namespace tega::scoring
