#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "tega/core/error.h"
#include "tega/tools/evaluate.h"
#include "tega/tools/load_run.h"

namespace tega::cli {

namespace {
struct EvalArguments {
  std::vector<std::string> models, names;
  std::string data, split = "test", json, lpips_vgg, lpips_lin, landmark_predictor, device;
};
}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArguments>();
  auto* cmd = app.add_subcommand("eval", "Evaluate trained avatars with the paper's protocol: test reenactment and novel "
                                         "view; JSON and a Markdown table (docs/render-eval-export.md).");
  cmd->add_option("--model", args->models, "Training run directory; repeat to compare several runs in one table.")
      ->required();
  cmd->add_option("--name", args->names, "Table row label of each --model, in order (default: the run's folder name).");
  cmd->add_option("--data", args->data, "Dataset directory (default: the one the first run's run.json names).");
  cmd->add_option("--split", args->split, "test: reenactment (test frames, train cameras) and novel view (train frames, "
                                          "test cameras); train: the training views.")
      ->check(CLI::IsMember({"test", "train"}));
  cmd->add_option("--json", args->json, "Output JSON file; the Markdown table goes beside it (.md).")->required();
  cmd->add_option("--lpips-vgg", args->lpips_vgg, "VGG-16 weights (safetensors, torchvision names) for LPIPS.");
  cmd->add_option("--lpips-lin", args->lpips_lin, "LPIPS linear-layer weights (safetensors, lpips package names).");
  cmd->add_option("--landmark-predictor", args->landmark_predictor,
                  "dlib 68-point shape predictor (.dat) for landmark_px: the landmarks it finds on the render and on "
                  "the ground truth in the same face box, compared (needs a build with dlib and the dataset's 68 "
                  "landmark_vertices; docs/render-eval-export.md#landmarks).");
  cmd->add_option("--device", args->device, "cpu or cuda (default: each run's device).");
  cmd->callback([args] {
    if (!args->names.empty() && args->names.size() != args->models.size())
      throw Error("tega eval: give one --name per --model (" + std::to_string(args->models.size()) + ")");
    if (args->lpips_vgg.empty() != args->lpips_lin.empty())
      throw Error("tega eval: LPIPS needs both --lpips-vgg and --lpips-lin");
    std::optional<tools::Lpips> lpips;
    if (!args->lpips_vgg.empty()) lpips = tools::Lpips::load(args->lpips_vgg, args->lpips_lin);
    tools::LandmarkPredictor landmark_predictor;  // empty: landmark_px skipped
    if (!args->landmark_predictor.empty())
      landmark_predictor = tools::load_landmark_predictor(args->landmark_predictor);
    const std::filesystem::path data =
        args->data.empty() ? tools::run_dataset(args->models.front()) : std::filesystem::path(args->data);

    std::vector<tools::ModelResult> results;
    std::optional<tools::EvalNotes> notes;
    for (size_t i = 0; i < args->models.size(); ++i) {
      const std::filesystem::path run_dir = args->models[i];
      tools::LoadedRun run = tools::load_run(run_dir, data, args->device);
      if (!notes) notes = tools::evaluation_notes(run.dataset, lpips.has_value(), args->landmark_predictor);
      tools::ModelResult result;
      result.name = args->names.empty() ? std::filesystem::absolute(run_dir).lexically_normal().filename().string()
                                        : args->names[i];
      if (result.name.empty()) result.name = run_dir.string();
      result.run = run_dir;
      result.iteration = run.avatar->iteration;
      result.gaussians = run.avatar->model.gaussians.size();
      result.splits = tools::evaluate_avatar(*run.avatar, run.dataset, args->split, lpips ? &*lpips : nullptr,
                                             landmark_predictor ? &landmark_predictor : nullptr);
      results.push_back(std::move(result));
    }
    tools::write_evaluation(results, *notes, args->json);
    std::cout << tools::evaluation_markdown(results, *notes);
  });
}

}  // namespace tega::cli
