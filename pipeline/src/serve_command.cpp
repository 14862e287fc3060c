#include <memory>

#include "commands.h"
#include "tega/serve/server.h"

namespace tega::cli {

void add_serve_command(CLI::App& app) {
  auto options = std::make_shared<serve::Options>();
  auto* cmd = app.add_subcommand("serve", "Play trained avatars in a browser: an HTTP server for the page, the run's "
                                          "cameras, takes and images, and its frames as a compact stream "
                                          "(docs/render-eval-export.md#serve).");
  cmd->add_option("RUN_OR_WORKSPACE", options->target, "A training run, or a tega run workspace (its train/<subject>/run).")
      ->required();
  cmd->add_option("--port", options->port, "Port to listen on (0: any free one).")->capture_default_str();
  cmd->add_option("--host", options->host,
                  "Address to listen on; the default answers this machine only (the server has no authentication).")
      ->capture_default_str();
  cmd->add_option("--device", options->device, "cpu or cuda: where frames are posed (default: the run's device).");
  cmd->add_option("--fps", options->fps, "Frame rate the page plays takes at (datasets do not record it).")
      ->capture_default_str();
  cmd->add_option("--cache-mb", [options](const CLI::results_t& r) {
    options->cache_bytes = std::stoll(r.front()) << 20;
    return true;
  }, "Megabytes of encoded frames kept for reuse (default 512).");
  cmd->add_option("--threads", options->threads, "Threads answering requests.")->capture_default_str();
  cmd->add_option("--meshes", options->meshes,
                  "A directory of tracked meshes (tega track's TRACKED/<take>, held-out takes, new performances) every "
                  "run plays as a take of its own (repeatable).");
  cmd->add_option("--splat", options->splats,
                  "An SPZ file (tega export --format spz) the page opens by name, ?splat=NAME (repeatable).");
  cmd->callback([options] { serve::serve(*options); });
}

}  // namespace tega::cli
