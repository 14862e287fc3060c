// `tega matte`: alpha mattes of every image of a capture's performance takes (docs/matting.md).
#include <cstdio>
#include <memory>

#include "commands.h"
#include "stage_options.h"
#include "tega/core/error.h"
#include "tega/matting/matte.h"

namespace tega::cli {

namespace {

struct MatteArguments {
  std::string capture, tracked, out, rig;
  std::vector<std::string> takes;
  int threads = -1;
  StageOptionFlags options;
};

}  // namespace

void add_matte_command(CLI::App& app) {
  auto args = std::make_shared<MatteArguments>();
  auto* cmd = app.add_subcommand(
      "matte",
      "Alpha mattes of every image of the performance takes, as recorded: the difference from the clean plate, "
      "the tracked mesh's silhouette for the head, unmixing against the known background at the edge "
      "(docs/matting.md).");
  cmd->add_option("--capture", args->capture, "The capture: CAPTURE/ with capture.json, rig.json and takes/.");
  cmd->add_option("--tracked", args->tracked, "TRACKED/ from tega track: identity.json, <take>/<frame>.bin/.json.");
  cmd->add_option("--out", args->out, "MATTES/: <take>/<camera>/<frame>.png, <take>/mattes.json.");
  cmd->add_option("--take", args->takes, "A take to matte (repeatable; default: every performance take).");
  cmd->add_option("--rig", args->rig, "Rig file (default: the capture's rig.json).");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all).");
  args->options.add_to(*cmd, "matte", "matte", "edge.band_px=4");
  cmd->callback([args] {
    auto options = args->options.load<matting::MatteOptions>();
    if (args->threads >= 0) options.threads = args->threads;
    if (args->options.print_if_asked(options)) return;
    if (args->capture.empty() || args->tracked.empty() || args->out.empty())
      throw Error("tega matte: --capture, --tracked and --out are required");
    const auto summary =
        matting::matte_capture({args->capture, args->tracked, args->out, args->takes, args->rig}, options);
    std::printf("%s: %d take(s), %d image(s) matted, %d already done, %d frame(s) not tracked%s\n", args->out.c_str(),
                summary.takes, summary.images, summary.images_kept, summary.frames_not_tracked,
                summary.clean_plate ? "" : " (no clean plate: mesh silhouettes only)");
  });
}

}  // namespace tega::cli
