// `tega synth`: the virtual studio. Parses flags and --set over an optional
// YAML config and calls tega::synth::render_virtual_studio().

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/synth/virtual_studio.h"

namespace tega::cli {
namespace {

struct SynthArgs {
  std::string out, head;
  int cameras = 0, frames = 0, width = 0, height = 0, threads = 0;
  int64_t seed = 0;
  bool force = false, truth_apart = false;
  StageOptionFlags options;
  CLI::Option *cameras_opt, *frames_opt, *width_opt, *height_opt, *seed_opt, *head_opt, *threads_opt;
};

synth::Options resolve_options(const SynthArgs& a) {
  auto o = a.options.load<synth::Options>();
  if (a.cameras_opt->count()) o.studio.cameras = a.cameras;
  if (a.width_opt->count()) o.studio.width = a.width;
  if (a.height_opt->count()) o.studio.height = a.height;
  if (a.frames_opt->count()) o.frames = a.frames;
  if (a.seed_opt->count()) o.seed = a.seed;
  if (a.head_opt->count()) o.head = a.head;
  if (a.threads_opt->count()) o.threads = a.threads;
  if (a.truth_apart) o.truth_apart = true;
  return o;
}

void run(const SynthArgs& a) {
  const synth::Options options = resolve_options(a);
  if (a.options.print_if_asked(options)) return;
  if (a.out.empty()) throw Error("tega synth: --out DIR is required");
  const synth::SynthSummary s = synth::render_virtual_studio(options, a.out, a.force);
  // With truth_apart the rig, ground truth and dataset lie beside the capture.
  const std::string truth = options.truth_apart ? synth::truth_directory(s.root).string() + "/" : std::string();
  std::cout << "wrote " << s.root.string() << " in " << Progress::format_duration(s.seconds) << "\n"
            << "  head:     " << s.head << "\n"
            << "  cameras:  " << s.cameras << " at " << s.width << "x" << s.height << " (" << truth << "rig.json)\n";
  for (const auto& t : s.takes)
    std::cout << "  take:     " << t.name << " (" << t.kind << ", " << t.frames << " frames)  takes/" << t.name << "/\n";
  if (s.calibration_skipped) std::cout << "  take:     calibration skipped (this build has no OpenCV)\n";
  std::cout << "  images:   " << s.images << "\n"
            << "  truth:    " << truth << "ground_truth/ (meshes, alpha, poses, expressions)\n"
            << "  dataset:  " << truth << "dataset/ (" << s.dataset_frames << " frames)\n";
}

}  // namespace

void add_synth_command(CLI::App& app) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* cmd = app.add_subcommand(
      "synth", "Render a synthetic capture of a head in a virtual studio: takes, rig, ground truth and a dataset.");
  cmd->add_option("--out", args->out, "Output directory (must not exist unless --force).");
  args->cameras_opt = cmd->add_option("--cameras", args->cameras, "Number of cameras (default 13).");
  args->frames_opt = cmd->add_option("--frames", args->frames, "Frames of each performance take (default 30).");
  args->width_opt = cmd->add_option("--width", args->width, "Image width in pixels (default 512).");
  args->height_opt = cmd->add_option("--height", args->height, "Image height in pixels (default 384).");
  args->seed_opt = cmd->add_option("--seed", args->seed, "Seed of skin texture, motion, board poses and noise (default 1).");
  args->head_opt = cmd->add_option("--head", args->head,
                                   "Blendshape model directory laid out like ICT-FaceKit (default: the built-in head).");
  args->threads_opt = cmd->add_option("--threads", args->threads, "Worker threads (default: one per hardware thread).");
  args->options.add_to(*cmd, "", "synth", "tracking_error.lag=0");
  cmd->add_flag("--force", args->force, "Replace an existing output directory.");
  cmd->add_flag("--truth-apart", args->truth_apart,
                "A raw capture in --out (capture.json and takes/); its rig, ground truth and dataset in OUT.truth/.");
  cmd->callback([args] { run(*args); });
}

}  // namespace tega::cli
