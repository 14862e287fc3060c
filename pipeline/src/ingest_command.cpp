// `tega ingest multiface`: a Multiface capture -> tega's native dataset
// (docs/multiface.md).
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/ingest/multiface.h"

namespace tega::cli {

namespace {
struct MultifaceArguments {
  std::string capture, out, template_obj, matte;
  std::vector<std::string> cameras, test_cameras, expressions, test_expressions;
  std::optional<int> frames, test_frames, downsample, threads;
  bool force = false;
  StageOptionFlags options;
};

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& n : names) text += (text.empty() ? "" : " ") + n;
  return text;
}
}  // namespace

void add_ingest_command(CLI::App& app) {
  auto* ingest = app.add_subcommand("ingest", "Turn an external capture into a tega dataset (docs/layouts.md#dataset).");
  ingest->require_subcommand(1);

  auto args = std::make_shared<MultifaceArguments>();
  auto* cmd = ingest->add_subcommand(
      "multiface",
      "Multiface capture (KRT, frame_list.txt, images/, tracked_mesh/) -> dataset: rig in metres without distortion, "
      "undistorted RGBA images matted by the mesh silhouette, world-space meshes, head poses, train/test split "
      "(docs/multiface.md).");
  cmd->add_option("--capture", args->capture, "Multiface capture directory (holds KRT and frame_list.txt).");
  cmd->add_option("--out", args->out, "Dataset directory to write; appears only once complete.");
  args->options.add_to(*cmd, "ingest", "ingest", "matte_dilation_px=60");
  cmd->add_option("--cameras", args->cameras,
                  "Cameras to use, by KRT name (default: all but those behind or directly above the head).");
  cmd->add_option("--test-cameras", args->test_cameras,
                  "Held-out cameras (default: 3 spread horizontally in front of the face).");
  cmd->add_option("--expressions", args->expressions, "Expression sequences to use (default: all in frame_list.txt).");
  cmd->add_option("--test-expressions", args->test_expressions,
                  "Name prefixes of the held-out sequences (default: EXP_ROM EXP_free_face).");
  cmd->add_option("--frames", args->frames, "Training frames, sampled uniformly (default 400).");
  cmd->add_option("--test-frames", args->test_frames,
                  "Test frames, sampled uniformly from the held-out sequences; 0 = all (default 100).");
  cmd->add_option("--template", args->template_obj,
                  "OBJ with the mesh topology and UVs (default: the neutral frame's tracked_mesh OBJ).");
  cmd->add_option("--matte", args->matte, "mesh (the mesh silhouette, dilated and feathered) or none (opaque).")
      ->check(CLI::IsMember({"mesh", "none"}));
  cmd->add_option("--downsample", args->downsample, "Image size divisor: 1 = full size (default), 2 = half.");
  cmd->add_option("--threads", args->threads, "Worker threads (default: one per hardware thread).");
  cmd->add_flag("--force", args->force, "Replace --out if it already exists.");

  cmd->callback([args] {
    auto options = args->options.load<ingest::IngestOptions>();
    if (!args->cameras.empty()) options.cameras = args->cameras;
    if (!args->test_cameras.empty()) options.test_cameras = args->test_cameras;
    if (!args->expressions.empty()) options.expressions = args->expressions;
    if (!args->test_expressions.empty()) options.test_expressions = args->test_expressions;
    if (args->frames) options.frames = *args->frames;
    if (args->test_frames) options.test_frames = *args->test_frames;
    if (!args->template_obj.empty()) options.template_obj = args->template_obj;
    if (!args->matte.empty()) options.matte = args->matte;
    if (args->downsample) options.downsample = *args->downsample;
    if (args->threads) options.threads = *args->threads;
    if (args->options.print_if_asked(options)) return;
    if (args->capture.empty() || args->out.empty()) throw Error("tega ingest multiface needs --capture and --out");
    const auto s = ingest::ingest_multiface(args->capture, args->out, options, args->force);
    std::cout << s.dataset.string() << ": " << s.train_frames << " train + " << s.test_frames << " test frames, "
              << s.images << " images; train cameras: " << joined(s.train_cameras)
              << "; test cameras: " << joined(s.test_cameras);
    if (s.missing_images > 0 || s.dropped_frames > 0)
      std::cout << "; left out: " << s.missing_images << " missing or unreadable images, " << s.dropped_frames
                << " frames with too few cameras (dataset.json: missing_images, dropped_frames)";
    std::cout << "\n";
  });
}

}  // namespace tega::cli
