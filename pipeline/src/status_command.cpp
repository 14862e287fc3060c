// `tega status WORKSPACE|CONFIG`: what is done, running, failed and stale.

#include <iostream>
#include <memory>

#include "available_commands.h"
#include "commands.h"
#include "tega/pipeline/orchestrator.h"
#include "tega/pipeline/status.h"

namespace tega::cli {
namespace {

namespace fs = std::filesystem;

struct StatusArguments {
  std::string target;
  bool json = false;
};

void status(const StatusArguments& args, const CLI::App& root) {
  pipeline::PipelineConfig config = fs::is_directory(args.target) ? pipeline::recorded_config(args.target)
                                                                   : pipeline::load_pipeline_config(args.target);
  const pipeline::StageGraph graph(std::move(config),
                                   [&](const std::vector<std::string>& path) { return has_subcommand(root, path); });
  const auto report = pipeline::workspace_status(graph, std::string("tega ") + TEGA_VERSION);
  std::cout << (args.json ? pipeline::status_json(report) : pipeline::status_text(report));
}

}  // namespace

void add_status_command(CLI::App& app) {
  auto args = std::make_shared<StatusArguments>();
  auto* cmd = app.add_subcommand(
      "status", "Show each stage's shards: done, stale, pending, running, failed (with the error and log), "
                "interrupted, blocked or unavailable (docs/pipeline.md#status).");
  cmd->add_option("target", args->target,
                  "A workspace (uses the config of its latest run) or a pipeline config (uses its workspace).")
      ->required();
  cmd->add_flag("--json", args->json, "Machine-readable output.");
  const CLI::App* root = &app;
  cmd->callback([args, root] { status(*args, *root); });
}

}  // namespace tega::cli
