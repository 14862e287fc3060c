// `tega track`: the head model fitted to every frame of a capture's takes (docs/tracking.md).
#include <memory>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/core/take.h"
#include "tega/scoring/tracking_scores.h"
#include "tega/tracking/tracking.h"

namespace tega::cli {

namespace {

struct TrackArguments {
  std::string capture, meshes, model, out, identity, rig, landmarks, frames;
  std::vector<std::string> takes;
  int threads = -1;
  StageOptionFlags options;
  bool studio_truth = false;
};

// Defaults, then the --config file's `track` section, then --set, then the flags given.
tracking::Options options_of(const TrackArguments& a) {
  auto options = a.options.load<tracking::Options>();
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
  cmd->add_option("--frames", args->frames,
                  "Frames A:B (B exclusive), A: or A of each take (default: all): a range starts afresh, and "
                  "processes tracking a take's ranges at once share one identity (docs/tracking.md#in-frame-ranges).");
  cmd->add_option("--rig", args->rig, "Rig file (default: the capture's rig.json).");
  cmd->add_option("--landmarks", args->landmarks, "A dlib 68-point shape predictor (.dat) for landmark terms.");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all).");
  args->options.add_to(*cmd, "track", "track", "icp_iterations=6");
  cmd->add_flag("--studio-truth", args->studio_truth,
                "Track nothing: write a virtual-studio capture's ground truth (its template, true meshes and poses) "
                "in the tracked layout, to run the later stages apart from tracking's error.");
  cmd->callback([args] {
    const tracking::Options options = options_of(*args);
    if (args->options.print_if_asked(options)) return;
    if (args->studio_truth) {
      if (args->capture.empty() || args->out.empty()) throw Error("tega track --studio-truth: --capture and --out are required");
      scoring::write_studio_truth_as_tracked(args->capture, args->out, args->takes);
      std::printf("%s: the studio's ground truth in the tracked layout\n", args->out.c_str());
      return;
    }
    if (args->capture.empty() || args->meshes.empty() || args->out.empty())
      throw Error("tega track: --capture, --meshes and --out are required");
    tracking::TrackRequest request{args->capture, args->takes, args->meshes, args->out, args->rig};
    if (!args->frames.empty()) parse_frame_range(args->frames, request.first_frame, request.end_frame);
    const auto summary = tracking::track_capture(request, options);
    std::printf("%s: %d take(s), %d frame(s) tracked, %d failed, %d without a scan, %d already done\n",
                args->out.c_str(), summary.takes, summary.frames_tracked, summary.frames_failed,
                summary.frames_skipped, summary.frames_kept);
  });
}

}  // namespace tega::cli
