#include <iostream>
#include <memory>

#include "commands.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/progress.h"
#include "tega/tools/export.h"
#include "tega/tools/load_run.h"
#include "tega/tools/render_avatar.h"

namespace tega::cli {

namespace {
struct ExportArguments {
  std::string model, data, out, meshes, mesh_pose, device, format;
  std::vector<std::string> frames;
  bool head_space = false, force = false;
};
}  // namespace

void add_export_command(CLI::App& app) {
  auto args = std::make_shared<ExportArguments>();
  auto* cmd = app.add_subcommand("export", "Export posed Gaussians as 3D Gaussian Splatting PLY or SPZ files for splat "
                                           "viewers (docs/render-eval-export.md).");
  cmd->add_option("--model", args->model, "Training run directory (RUN of tega train).")->required();
  cmd->add_option("--out", args->out,
                  "One frame: the .ply (.spz) file. Several frames (or --meshes): a directory of <frame>.ply (.spz).")
      ->required();
  cmd->add_option("--format", args->format,
                  "ply (3DGS layout, float32) or spz (Niantic's compressed splats, about a tenth of the bytes); "
                  "default: --out's extension, else ply.")
      ->check(CLI::IsMember({"ply", "spz"}));
  cmd->add_option("--frame", args->frames, "Dataset frame id(s), comma-separated; 'all' for every frame, 'first' for the first training frame.")->delimiter(',');
  cmd->add_option("--meshes", args->meshes,
                  "Export a directory of meshes (.bin/.obj/.ply, template topology, world space) instead of dataset frames.");
  cmd->add_option("--mesh-pose", args->mesh_pose, "Dataset frame whose head pose the --meshes take (default: the first training frame).");
  cmd->add_flag("--head-space", args->head_space, "The --meshes are in head space: move them by the --mesh-pose pose first.");
  cmd->add_option("--data", args->data, "Dataset directory (default: the one RUN/run.json names).");
  cmd->add_option("--device", args->device, "cpu or cuda (default: the run's device).");
  cmd->add_flag("--force", args->force, "Replace an existing output directory (a single file is always replaced atomically).");
  cmd->callback([args] {
    if (args->frames.empty() == args->meshes.empty()) throw Error("tega export: give --frame or --meshes (one of them)");
    const std::filesystem::path out = args->out;
    const tools::ExportFormat format = tools::export_format(args->format, out);
    const std::string extension = tools::file_extension(format);
    const std::string format_name = format == tools::ExportFormat::spz ? "SPZ" : "PLY";
    tools::LoadedRun run = tools::load_run(args->model, args->data, args->device);
    const Dataset& dataset = run.dataset;
    std::vector<tools::RenderFrame> frames;
    if (!args->meshes.empty()) {
      const std::string pose_frame = args->mesh_pose.empty() ? dataset.train.frames.at(0) : args->mesh_pose;
      frames = tools::mesh_sequence(args->meshes, dataset.template_mesh.num_vertices(),
                                    dataset.frame(pose_frame).head_to_world, args->head_space);
    } else {
      std::vector<std::string> ids = args->frames;
      if (ids == std::vector<std::string>{"all"}) {
        ids.clear();
        for (const auto& f : dataset.frames) ids.push_back(f.id);
      } else if (ids == std::vector<std::string>{"first"}) {
        ids = {dataset.train.frames.at(0)};
      }
      frames = tools::dataset_frames(dataset, ids);
    }

    trainer::TrainedAvatar& avatar = *run.avatar;
    const auto cloud = [&](const tools::RenderFrame& f) {
      return tools::export_frame(avatar.model, avatar.model.frame_input(f.world_vertices, f.head_to_world), avatar.phase);
    };
    const auto write = [&](const tools::RenderFrame& f, const std::filesystem::path& file) {
      tools::write_gaussians(cloud(f), file, format, avatar.options.antialiased);
    };
    if (frames.size() == 1 && args->meshes.empty() && out.extension() == extension) {
      write(frames.front(), out);
      std::cout << "wrote " << avatar.model.gaussians.size() << " Gaussians of frame " << frames.front().id << " to "
                << out.string() << "\n";
      return;
    }
    if (out.extension() == extension)
      throw Error(out, "several frames go to a directory of <frame>" + extension + " files: give --out a directory name");
    StagedDirectory staged(out, args->force);
    Progress progress("export", static_cast<int64_t>(frames.size()), "frames");
    for (const auto& f : frames) {
      write(f, staged.path() / (f.id + extension));
      progress.advance();
    }
    progress.finish();
    staged.commit();
    std::cout << "wrote " << frames.size() << " " << format_name << " files of " << avatar.model.gaussians.size() << " Gaussians to "
              << out.string() << "\n";
  });
}

}  // namespace tega::cli
