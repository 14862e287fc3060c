// `tega track`: the head model fitted to every frame of a capture's takes (docs/tracking.md).
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/tracking/evaluation.h"
#include "tega/tracking/tracking.h"

namespace tega::cli {

namespace {

struct TrackArguments {
  std::string capture, meshes, model, out, identity, rig, landmarks, config;
  std::vector<std::string> takes, overrides;
  int threads = -1;
  bool print_options = false;
  bool studio_truth = false;
};

// Defaults, then the --config file's `track` section, then --set, then the flags given.
tracking::Options options_of(const TrackArguments& a) {
  tracking::Options options;
  if (!a.config.empty()) load_options(options, a.config, "track");
  apply_overrides(options, a.overrides);
  if (!a.model.empty()) options.model = a.model;
  if (!a.identity.empty()) options.identity = a.identity;
  if (!a.landmarks.empty()) options.landmarks.model = a.landmarks;
  if (a.threads >= 0) options.threads = a.threads;
  return options;
}

}  // namespace

void add_track_command(CLI::App& app) {
  auto args = std::make_shared<TrackArguments>();
  auto* cmd = app.add_subcommand(
      "track",
      "Fit the blendshape head model to every frame's multi-view stereo mesh: the subject's identity once, then "
      "head pose, expression and per-vertex detail per frame (docs/tracking.md).");
  cmd->add_option("--capture", args->capture, "The capture: CAPTURE/ with capture.json, rig.json and takes/.");
  cmd->add_option("--take", args->takes, "A take to track (repeatable; default: every performance take).");
  cmd->add_option("--meshes", args->meshes, "MESHES/ from tega mvs: <take>/<frame>.ply.");
  cmd->add_option("--model", args->model, "The head model directory (ICT-FaceKit layout, with vertex_indices.json); sets the model option.");
  cmd->add_option("--out", args->out, "TRACKED/: identity.json, <take>/<frame>.bin/.json, <take>/report/.");
  cmd->add_option("--identity", args->identity,
                  "An identity.json from an earlier run of this subject: reused instead of fitting one.");
  cmd->add_option("--rig", args->rig, "Rig file (default: the capture's rig.json).");
  cmd->add_option("--landmarks", args->landmarks, "A dlib 68-point shape predictor (.dat) for landmark terms.");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all).");
  cmd->add_option("--config", args->config, "YAML file whose `track` section sets options (see --print-options).");
  cmd->add_option("--set", args->overrides, "Override one option, e.g. --set icp_iterations=6 (repeatable).");
  cmd->add_flag("--print-options", args->print_options, "Print every track option with its default and exit.");
  cmd->add_flag("--studio-truth", args->studio_truth,
                "Track nothing: write a virtual-studio capture's ground truth (its template, true meshes and poses) "
                "in the tracked layout, to run the later stages apart from tracking's error.");
  cmd->callback([args] {
    const tracking::Options options = options_of(*args);
    if (args->print_options) {
      std::cout << "track:\n";
      std::istringstream yaml(options_to_yaml(options));
      for (std::string line; std::getline(yaml, line);) std::cout << "  " << line << "\n";
      return;
    }
    if (args->studio_truth) {
      if (args->capture.empty() || args->out.empty()) throw Error("tega track --studio-truth: --capture and --out are required");
      tracking::write_studio_truth_as_tracked(args->capture, args->out, args->takes);
      std::printf("%s: the studio's ground truth in the tracked layout\n", args->out.c_str());
      return;
    }
    if (args->capture.empty() || args->meshes.empty() || args->out.empty())
      throw Error("tega track: --capture, --meshes and --out are required");
    tracking::TrackRequest request{args->capture, args->takes, args->meshes, args->out, args->rig};
    const auto summary = tracking::track_capture(request, options);
    std::printf("%s: %d take(s), %d frame(s) tracked, %d failed, %d without a scan, %d already done\n",
                args->out.c_str(), summary.takes, summary.frames_tracked, summary.frames_failed,
                summary.frames_skipped, summary.frames_kept);
  });
}

}  // namespace tega::cli
