// `tega calibrate`: the rig from a calibration take (docs/calibration.md).
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "stage_options.h"
#include "tega/calibrate/calibration.h"
#include "tega/calibrate/report.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/rig.h"

namespace tega::cli {

namespace {

struct CalibrateArguments {
  std::string take, board, out, init;
  int dpi = 300;
  calibrate::CalibrationOptions options;  // defaults, then the flags given
  StageOptionFlags option_flags;
};

// The options: defaults, then the --config file's `calibrate` section, then --set, then the flags given.
calibrate::CalibrationOptions options_of(const CLI::App& cmd, const CalibrateArguments& args) {
  auto options = args.option_flags.load<calibrate::CalibrationOptions>();
  const auto& flags = args.options;
  const auto given = [&](const char* flag) { return cmd.get_option(flag)->count() > 0; };
  if (given("--world")) options.world = flags.world;
  if (given("--world-camera")) options.world_camera = flags.world_camera;
  if (given("--world-board-frame")) options.world_board_frame = flags.world_board_frame;
  if (given("--robust-loss-px")) options.robust_loss_px = flags.robust_loss_px;
  if (given("--outlier-px")) options.outlier_px = flags.outlier_px;
  if (given("--free-k3")) options.fix_k3 = flags.fix_k3;
  if (given("--refine-init-intrinsics")) options.refine_init_intrinsics = flags.refine_init_intrinsics;
  if (given("--min-views")) options.min_views = flags.min_views;
  if (given("--threads")) options.threads = flags.threads;
  return options;
}

// Each camera's image size, from its first image of the take.
std::vector<calibrate::CameraSize> camera_sizes(const TakeInfo& take) {
  std::vector<calibrate::CameraSize> sizes;
  for (const auto& name : take.cameras) {
    int frame = 0;
    while (frame < take.frames && !take.has_image(name, frame)) ++frame;
    if (frame == take.frames) throw Error(take.folder, "camera " + name + " has no image in this take");
    const auto file = take.image_path(name, frame);
    if (file.extension() == ".png") {
      const ImageHeader header = read_image_header(file);
      sizes.push_back({name, header.width, header.height});
    } else {
      const Image8 image = read_image_u8(file);
      sizes.push_back({name, image.width, image.height});
    }
  }
  return sizes;
}

void add_board_command(CLI::App& calibrate, const std::shared_ptr<CalibrateArguments>& args) {
  auto* cmd = calibrate.add_subcommand("board", "Write a printable image of the board a board file describes.");
  cmd->add_option("--board", args->board, "Board file (YAML).")->required();
  cmd->add_option("--out", args->out, "PNG to write.")->required();
  cmd->add_option("--dpi", args->dpi, "Printer resolution in dots per inch (default 300).");
  cmd->callback([args] {
    const auto board = calibrate::load_board(args->board);
    const Image8 image = calibrate::draw_board(board, args->dpi);
    write_image(image, args->out);
    std::printf("%s: %dx%d pixels at %d dpi = %.1f x %.1f cm; print at 100%% scale and measure a square (%.1f mm)\n",
                args->out.c_str(), image.width, image.height, args->dpi, image.width / double(args->dpi) * 2.54,
                image.height / double(args->dpi) * 2.54, board.options.square_m * 1000);
  });
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArguments>();
  auto& o = args->options;
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate the rig from a calibration take: board detection, per-camera intrinsics, pose graph, bundle "
      "adjustment; writes the rig and its report (docs/calibration.md).");
  cmd->require_subcommand(0, 1);
  cmd->add_option("--take", args->take, "The calibration take: CAPTURE/takes/<take>.");
  cmd->add_option("--board", args->board, "Board file (YAML; docs/calibration.md#board-files).");
  cmd->add_option("--out", args->out, "Rig file to write (rig.json); the report goes beside it.");
  cmd->add_option("--init", args->init,
                  "A previous rig to refine (daily re-calibration): its intrinsics start the solve, so fewer board "
                  "poses suffice, and the report says how far each camera moved.");
  cmd->add_option("--world", o.world, "camera (default) or board: what the world frame is.");
  cmd->add_option("--world-camera", o.world_camera, "world camera: its name (default: the first camera).");
  cmd->add_option("--world-board-frame", o.world_board_frame,
                  "world board: the frame whose board pose is the world (default: the frame most cameras see).");
  cmd->add_option("--robust-loss-px", o.robust_loss_px, "Huber loss scale in pixels (default 1).");
  cmd->add_option("--outlier-px", o.outlier_px, "Corners further than this after the first solve are removed (default 2).");
  cmd->add_flag("!--free-k3", o.fix_k3, "Estimate k3 too (wide-angle lenses); by default it stays at 0 or --init's.");
  cmd->add_flag("--refine-init-intrinsics", o.refine_init_intrinsics,
                "With --init: solve for the intrinsics too (needs a full calibration take); by default they stay.");
  cmd->add_option("--min-views", o.min_views, "Board views a camera needs for its own intrinsics (default 4).");
  cmd->add_option("--threads", o.threads, "Threads for detection and the solver (default: all).");
  args->option_flags.add_to(*cmd, "calibrate", "calibration", "outlier_px=1.5");
  add_board_command(*cmd, args);
  cmd->callback([cmd, args] {
    if (!cmd->get_subcommands().empty()) return;
    args->options = options_of(*cmd, *args);
    if (args->option_flags.print_if_asked(args->options)) return;
    if (args->take.empty() || args->board.empty() || args->out.empty())
      throw Error("tega calibrate needs --take, --board and --out");
    if (args->options.world != "camera" && args->options.world != "board")
      throw Error("--world must be camera or board, not '" + args->options.world + "'");
    const TakeInfo take = read_take(args->take);
    const auto board = calibrate::load_board(args->board);
    const auto sizes = camera_sizes(take);
    const auto views = calibrate::detect_board_in_take(take, board, args->options.threads);
    if (views.empty())
      throw Error(take.folder, "no board found in any image: does " + args->board + " (" + board.options.type + ", " +
                                   std::to_string(board.options.squares_x) + "x" +
                                   std::to_string(board.options.squares_y) + " squares) match the board filmed?");
    std::optional<Rig> init;
    if (!args->init.empty()) init = read_rig_json(args->init);
    const auto calibration = calibrate::calibrate_rig(views, board, sizes, args->options, init ? &*init : nullptr);
    calibrate::write_calibration(calibration, args->out);
    std::cout << calibrate::calibration_summary(calibration);
    std::cout << args->out << " written, with its report beside it\n";
  });
}

}  // namespace tega::cli
