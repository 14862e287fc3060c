// `tega mvs`: per-frame multi-view stereo meshes of a take (docs/mvs.md).
#include <memory>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/core/take.h"
#include "tega/mvs/reconstruction.h"

namespace tega::cli {

namespace {

struct MvsArguments {
  std::string capture, out, rig, frames, device, images, workspace_dir, map_type = "geometric";
  double rig_metres_per_unit = 1.0;
  std::vector<std::string> takes;
  int threads = -1;
  bool workspace = false;
  StageOptionFlags options;
};

// Defaults, then the --config file's `mvs` section, then --set, then the flags given.
mvs::Options options_of(const MvsArguments& a) {
  auto options = a.options.load<mvs::Options>();
  if (!a.device.empty()) options.device = a.device;
  if (a.threads >= 0) options.threads = a.threads;
  if (a.workspace) options.write_workspace = true;
  return options;
}

void add_shared_options(CLI::App& cmd, const std::shared_ptr<MvsArguments>& args) {
  cmd.add_option("--device", args->device, "cpu, cuda or auto (default auto: cuda when a GPU is available).");
  cmd.add_option("--threads", args->threads, "CPU worker threads (default: all).");
  args->options.add_to(cmd, "mvs", "mvs", "patch_match.iterations=6");
}

void add_photos_command(CLI::App& mvs_command, const std::shared_ptr<MvsArguments>& args) {
  auto* cmd = mvs_command.add_subcommand(
      "photos", "A mesh from an ordinary calibrated photo set: one image per camera of the rig (docs/mvs.md#photo-sets).");
  cmd->add_option("--images", args->images, "Folder of images named <camera>.png/.jpg/.tif.")->required();
  cmd->add_option("--rig", args->rig, "rig.json, or a COLMAP text model directory (cameras.txt, images.txt).")->required();
  cmd->add_option("--rig-metres-per-unit", args->rig_metres_per_unit, "A COLMAP model's unit in metres (default 1).");
  cmd->add_option("--out", args->out, "The mesh to write (.ply).")->required();
  cmd->add_option("--workspace", args->workspace_dir, "Also write a COLMAP dense workspace here.");
  add_shared_options(*cmd, args);
  cmd->callback([args] {
    const mvs::Options options = options_of(*args);
    if (args->options.print_if_asked(options)) return;
    mvs::PhotoRequest request{args->images, args->rig, args->rig_metres_per_unit, args->out, args->workspace_dir};
    const auto t = mvs::reconstruct_photos(request, options);
    std::printf("%s: load %.1f s, depth %.1f s, fusion %.1f s, surface %.1f s\n", args->out.c_str(), t.load_s, t.depth_s,
                t.fusion_s, t.surface_s);
  });
}

void add_mesh_workspace_command(CLI::App& mvs_command, const std::shared_ptr<MvsArguments>& args) {
  auto* cmd = mvs_command.add_subcommand(
      "mesh-workspace",
      "Fuse and mesh the depth maps of a COLMAP dense workspace (COLMAP's patch_match_stereo output or tega's).");
  cmd->add_option("--workspace", args->workspace_dir, "The workspace: images/, sparse/ (text), stereo/.")->required();
  cmd->add_option("--type", args->map_type, "Depth maps to read: geometric (default) or photometric.");
  cmd->add_option("--out", args->out, "The mesh to write (.ply).")->required();
  add_shared_options(*cmd, args);
  cmd->callback([args] {
    const mvs::Options options = options_of(*args);
    if (args->options.print_if_asked(options)) return;
    const auto t = mvs::mesh_workspace(args->workspace_dir, args->out, options, args->map_type);
    std::printf("%s: load %.1f s, fusion %.1f s, surface %.1f s\n", args->out.c_str(), t.load_s, t.fusion_s, t.surface_s);
  });
}

}  // namespace

void add_mvs_command(CLI::App& app) {
  auto args = std::make_shared<MvsArguments>();
  auto* cmd = app.add_subcommand(
      "mvs",
      "Multi-view stereo: a mesh per frame of a capture's performance takes (PatchMatch depth maps, fusion, "
      "screened Poisson), written as MESHES/<take>/<frame>.ply in metres, world space (docs/mvs.md).");
  cmd->add_option("--capture", args->capture, "The capture: CAPTURE/ with capture.json, rig.json and takes/.");
  cmd->add_option("--take", args->takes, "A take to mesh (repeatable; default: every performance take).");
  cmd->add_option("--out", args->out, "MESHES/: <take>/<frame>.ply and <take>/<frame>.json per frame.");
  cmd->add_option("--rig", args->rig, "Rig file (default: the capture's rig.json).");
  cmd->add_option("--frames", args->frames, "Frames A:B (B exclusive), A: or A (default: all).");
  cmd->add_flag("--workspace", args->workspace,
                "Also write each frame's COLMAP dense workspace (MESHES/<take>/colmap/<frame>/).");
  add_shared_options(*cmd, args);
  cmd->require_subcommand(0, 1);
  add_photos_command(*cmd, args);
  add_mesh_workspace_command(*cmd, args);
  cmd->callback([cmd, args] {
    if (!cmd->get_subcommands().empty()) return;
    const mvs::Options options = options_of(*args);
    if (args->options.print_if_asked(options)) return;
    if (args->capture.empty() || args->out.empty()) throw Error("tega mvs: --capture and --out are required");
    mvs::MvsRequest request;
    request.capture = args->capture;
    request.takes = args->takes;
    request.out = args->out;
    request.rig = args->rig;
    if (!args->frames.empty()) parse_frame_range(args->frames, request.first_frame, request.end_frame);
    const auto summary = mvs::reconstruct_capture(request, options);
    std::printf("%s: %d take(s), %d frame(s) meshed, %d already done\n", args->out.c_str(), summary.takes,
                summary.frames_done, summary.frames_skipped);
  });
}

}  // namespace tega::cli
