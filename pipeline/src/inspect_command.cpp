#include <iostream>
#include <memory>

#include "commands.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/tools/liveness.h"
#include "tega/tools/load_run.h"

namespace tega::cli {

namespace {
struct InspectArguments {
  std::vector<std::string> models;
  std::string data, json, device;
  tools::LivenessOptions options;
};
}  // namespace

void add_inspect_command(CLI::App& app) {
  auto args = std::make_shared<InspectArguments>();
  auto* cmd = app.add_subcommand(
      "inspect", "Liveness of each part of trained avatars: how far the deformation field moves the Gaussians, the "
                 "shading multiplier's range, Gaussians that changed triangle, the gradient each part gets "
                 "(docs/render-eval-export.md#liveness).");
  cmd->add_option("--model", args->models, "Training run directory (repeatable).")->required();
  cmd->add_option("--data", args->data, "Dataset directory (default: the one each run's run.json names).");
  cmd->add_option("--json", args->json, "Output JSON file (one entry per model); the Markdown goes beside it (.md).");
  cmd->add_option("--gradient-views", args->options.gradient_views,
                  "Training views the gradients are averaged over (default 8).");
  cmd->add_option("--truth", args->options.truth,
                  "A tega synth capture (with truth_apart, its CAPTURE.truth/): how far the dataset's meshes put the "
                  "Gaussians from where its true meshes would, and how much of that the deformation field undoes.");
  cmd->add_option("--device", args->device, "cpu or cuda (default: each run's device).");
  cmd->callback([args] {
    nlohmann::json all = nlohmann::json::array();
    std::string markdown = "# Liveness of each part (tega inspect)\n\n";
    for (const auto& model : args->models) {
      tools::LoadedRun run = tools::load_run(model, args->data, args->device);
      const tools::Liveness liveness = tools::inspect_avatar(*run.avatar, run.dataset, args->options);
      nlohmann::json entry = tools::liveness_json(liveness);
      entry["run"] = model;
      all.push_back(entry);
      const std::string text = tools::liveness_markdown(liveness, std::filesystem::path(model).filename().string());
      std::cout << text << "\n";
      markdown += text + "\n";
    }
    if (!args->json.empty()) {
      const std::filesystem::path file = args->json;
      if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
      write_text_atomic(file, all.dump(2) + "\n");
      std::filesystem::path md = file;
      write_text_atomic(md.replace_extension(".md"), markdown);
    }
  });
}

}  // namespace tega::cli
