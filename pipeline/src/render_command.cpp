#include <iostream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "tega/core/error.h"
#include "tega/core/rig.h"
#include "tega/tools/load_run.h"
#include "tega/tools/render_avatar.h"

namespace tega::cli {

namespace {

struct RenderArguments {
  std::string model, data, out, camera_file, meshes, mesh_pose, format = "png", device;
  std::vector<std::string> cameras, frames;
  int orbit = 0, width = 0, height = 0;
  double fps = 30;
  bool head_space = false, no_side_by_side = false, no_video = false, force = false;
};

// The head centre the orbit turns about: the middle of the first frame's bounding box.
Eigen::Vector3d mesh_centre(const Vertices& v) {
  return ((v.colwise().minCoeff() + v.colwise().maxCoeff()) / 2).transpose().cast<double>();
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArguments>();
  auto* cmd = app.add_subcommand("render", "Render a trained avatar: dataset frames or new meshes, from dataset, orbit or "
                                           "file cameras, to images and videos (docs/render-eval-export.md).");
  cmd->add_option("--model", args->model, "Training run directory (RUN of tega train).")->required();
  cmd->add_option("--out", args->out, "Output directory (written atomically; see --force).")->required();
  cmd->add_option("--data", args->data, "Dataset directory (default: the one RUN/run.json names).");
  cmd->add_option("--cameras", args->cameras,
                  "Dataset cameras by name, comma-separated (default: every rig camera, unless --orbit or "
                  "--camera-file is given).")
      ->delimiter(',');
  cmd->add_option("--orbit", args->orbit,
                  "Add N turntable cameras circling the head at the dataset cameras' mean distance and height.");
  cmd->add_option("--camera-file", args->camera_file, "Add the cameras of a tega rig file (docs/rig-files.md; undistorted pinholes).");
  cmd->add_option("--frames", args->frames,
                  "Dataset frames by id, comma-separated (default: the test split's frames; 'all' for every frame).")
      ->delimiter(',');
  cmd->add_option("--meshes", args->meshes,
                  "Render a directory of meshes (.bin/.obj/.ply, template topology, world space; name order) instead "
                  "of dataset frames.");
  cmd->add_option("--mesh-pose", args->mesh_pose,
                  "Dataset frame whose head pose the --meshes take (default: the first training frame).");
  cmd->add_flag("--head-space", args->head_space, "The --meshes are in head space: move them by the --mesh-pose pose first.");
  cmd->add_option("--width", args->width, "Render width in pixels, up to 4096 (alone: keeps the aspect ratio).");
  cmd->add_option("--height", args->height, "Render height in pixels, up to 4096 (alone: keeps the aspect ratio).");
  cmd->add_option("--format", args->format, "Image format: png or exr (exr needs OpenImageIO; float values).")
      ->check(CLI::IsMember({"png", "exr"}));
  cmd->add_flag("--no-side-by-side", args->no_side_by_side, "Skip the render | ground-truth strips.");
  cmd->add_flag("--no-video", args->no_video, "Skip the MP4 videos.");
  cmd->add_option("--fps", args->fps, "Video frame rate (default 30).");
  cmd->add_option("--device", args->device, "cpu or cuda (default: the run's device).");
  cmd->add_flag("--force", args->force, "Replace an existing --out.");
  cmd->callback([args] {
    tools::LoadedRun run = tools::load_run(args->model, args->data, args->device);
    const Dataset& dataset = run.dataset;

    tools::RenderJob job;
    job.out = args->out;
    job.format = args->format;
    job.side_by_side = !args->no_side_by_side;
    job.video = !args->no_video;
    job.fps = args->fps;
    job.replace_existing = args->force;

    if (!args->meshes.empty()) {
      if (!args->frames.empty()) throw Error("tega render: give --frames or --meshes, not both");
      const std::string pose_frame = args->mesh_pose.empty() ? dataset.train.frames.at(0) : args->mesh_pose;
      job.frames = tools::mesh_sequence(args->meshes, dataset.template_mesh.num_vertices(),
                                        dataset.frame(pose_frame).head_to_world, args->head_space);
    } else {
      std::vector<std::string> ids = args->frames.empty() ? dataset.test.frames : args->frames;
      if (ids == std::vector<std::string>{"all"}) {
        ids.clear();
        for (const auto& f : dataset.frames) ids.push_back(f.id);
      }
      job.frames = tools::dataset_frames(dataset, ids);
    }

    const bool dataset_cameras = !args->cameras.empty() || (args->orbit == 0 && args->camera_file.empty());
    const std::vector<std::string> names = args->cameras.empty() ? dataset.rig.camera_names() : args->cameras;
    if (dataset_cameras)
      for (const auto& name : names) job.cameras.push_back({tools::resized(dataset.rig.camera(name), args->width, args->height), true});
    if (args->orbit > 0) {
      const Camera& intrinsics = args->cameras.empty() ? dataset.rig.cameras.front() : dataset.rig.camera(args->cameras.front());
      for (const Camera& c : tools::orbit_cameras(dataset.rig.cameras, mesh_centre(job.frames.front().world_vertices),
                                                  args->orbit, tools::resized(intrinsics, args->width, args->height)))
        job.cameras.push_back({c, false});
    }
    if (!args->camera_file.empty()) {
      const Rig rig = read_rig_json(args->camera_file);
      for (const Camera& c : rig.cameras) {
        if (c.has_distortion())
          throw Error(args->camera_file, "camera " + c.name + " has lens distortion; the avatar renders pinholes");
        job.cameras.push_back({tools::resized(c, args->width, args->height), false});
      }
    }

    const tools::RenderSummary summary = tools::render_avatar(*run.avatar, dataset, job);
    std::cout << "rendered " << summary.images << " images (" << summary.side_by_side << " beside ground truth) into "
              << job.out.string() << "\n";
    for (const auto& video : summary.videos) std::cout << "video: " << video.string() << "\n";
    if (!summary.video_note.empty()) std::cout << "no video: " << summary.video_note << "\n";
  });
}

}  // namespace tega::cli
