// `tega landmarks train`: a dlib 68-point landmark predictor trained on
// virtual-studio captures and their true landmarks (docs/tracking.md).
#include <cstdio>
#include <memory>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/scoring/landmark_capture_training.h"

namespace tega::cli {

namespace {

struct LandmarksTrainArguments {
  std::vector<std::string> captures;
  std::string out, model;
  int threads = -1;
  StageOptionFlags options;
};

// Defaults, then the --config file's `landmarks` section, then --set, then the flags given.
scoring::LandmarkPredictorOptions options_of(const LandmarksTrainArguments& a) {
  auto options = a.options.load<scoring::LandmarkPredictorOptions>();
  if (!a.model.empty()) options.model = a.model;
  if (a.threads >= 0) options.training.threads = a.threads;
  return options;
}

void train(const LandmarksTrainArguments& args) {
  const scoring::LandmarkPredictorOptions options = options_of(args);
  if (args.options.print_if_asked(options)) return;
  if (args.captures.empty() || args.out.empty())
    throw Error("tega landmarks train: --capture (one or more) and --out are required");
  const std::vector<std::filesystem::path> captures(args.captures.begin(), args.captures.end());
  const auto summary = scoring::train_landmark_predictor_on_captures(captures, options, args.out);
  int trained = 0;
  for (const int count : summary.samples_per_capture) trained += count;
  std::printf("%s: trained on %d images of %zu capture(s) in %.0f s\n", args.out.c_str(), trained, captures.size(),
              summary.training_seconds);
  if (summary.held_out_images > 0)
    std::printf("held-out fit (%d images of %s, %d landmarks, boxes from the true landmarks): median %.2f px, "
                "95th percentile %.2f px\n",
                summary.held_out_images, args.captures.back().c_str(), summary.held_out_landmarks,
                summary.held_out_median_px, summary.held_out_p95_px);
  else
    std::printf("no held-out images (hold_out is off, or the last capture has one sampled frame per take)\n");
}

}  // namespace

void add_landmarks_command(CLI::App& app) {
  auto* landmarks =
      app.add_subcommand("landmarks", "Landmark predictors for tracking and evaluation (docs/tracking.md).");
  landmarks->require_subcommand(1);
  auto args = std::make_shared<LandmarksTrainArguments>();
  auto* cmd = landmarks->add_subcommand(
      "train",
      "Train a dlib 68-point landmark predictor on virtual-studio captures (their photos and true landmarks), "
      "write it atomically and report its error on held-out frames.");
  cmd->add_option("--capture", args->captures,
                  "A virtual-studio capture (tega synth --head MODEL) of a training subject (repeatable).");
  cmd->add_option("--out", args->out, "The predictor to write (.dat), as tega track --landmarks reads it.");
  cmd->add_option("--model", args->model,
                  "Head model directory with vertex_indices.json (default: the model each capture was rendered with).");
  cmd->add_option("--threads", args->threads, "Training threads (default: all).");
  args->options.add_to(*cmd, "landmarks", "landmark training", "sampling.frame_stride=2");
  cmd->callback([args] { train(*args); });
}

}  // namespace tega::cli
