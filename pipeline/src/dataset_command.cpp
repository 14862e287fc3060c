#include <iostream>
#include <memory>

#include "commands.h"
#include "tega/core/dataset.h"

#ifdef TEGA_HAVE_MATTING
#include "stage_options.h"
#include "tega/matting/dataset_build.h"
#endif

namespace tega::cli {

namespace {

void add_check_command(CLI::App& dataset) {
  auto* check = dataset.add_subcommand(
      "check", "Check a dataset the way training does before it starts: manifest, rig, template, split, "
               "every image (exists, size, RGBA) and every mesh (vertex count). Exits non-zero naming "
               "the first offending file.");
  auto root = std::make_shared<std::string>();
  check->add_option("--data", *root, "Dataset directory (holds dataset.json).")->required();
  check->callback([root] {
    const Dataset d = read_dataset(*root);
    validate_dataset(d);
    std::cout << *root << ": ok: " << d.frames.size() << " frames (" << d.train.frames.size() << " train, "
              << d.test.frames.size() << " test), " << d.rig.cameras.size() << " cameras ("
              << d.train.cameras.size() << " train, " << d.test.cameras.size() << " test), template "
              << d.template_mesh.num_vertices() << " vertices / " << d.template_mesh.num_faces()
              << " triangles\n";
  });
}

#ifdef TEGA_HAVE_MATTING
struct BuildArguments {
  matting::DatasetBuildRequest request;
  std::string config;
  std::vector<std::string> overrides;
  bool print_options = false;
};

void add_build_command(CLI::App& dataset) {
  auto args = std::make_shared<BuildArguments>();
  auto* build = dataset.add_subcommand(
      "build", "Assemble the dataset from a capture, its tracked meshes and its mattes: frames sampled over the "
               "performance takes, images undistorted, downsampled and matted into RGBA, the split "
               "(docs/matting.md#building-the-dataset).");
  build->add_option("--capture", args->request.capture, "The capture: CAPTURE/ with capture.json, rig.json, takes/.");
  build->add_option("--tracked", args->request.tracked, "TRACKED/ from tega track.");
  build->add_option("--mattes", args->request.mattes,
                    "MATTES/ from tega matte. Without it, the sampled images are matted here with the options' "
                    "`matte` section (the same method; each photo is decoded once).");
  build->add_option("--out", args->request.out,
                    "Dataset directory to write; appears only once complete (an interrupted run leaves "
                    "OUT.partial/, which the same command continues).");
  build->add_option("--rig", args->request.rig, "Rig file (default: the capture's rig.json).");
  build->add_option("--config", args->config, "YAML file whose `dataset` section sets options (see --print-options).");
  build->add_option("--set", args->overrides, "Override one option, e.g. --set frames=100 (repeatable).");
  build->add_flag("--force", args->request.replace_existing, "Replace --out if it already exists.");
  build->add_flag("--print-options", args->print_options, "Print every dataset option with its default and exit.");
  build->callback([args] {
    const auto options = load_stage_options<matting::DatasetBuildOptions>(args->config, "dataset", args->overrides);
    if (args->print_options) return print_stage_options("dataset", options);
    const auto& r = args->request;
    if (r.capture.empty() || r.tracked.empty() || r.out.empty())
      throw Error("tega dataset build: --capture, --tracked and --out are required");
    const auto s = matting::build_dataset(r, options);
    std::cout << s.dataset.string() << ": " << s.train_frames << " train + " << s.test_frames << " test frames, "
              << s.train_cameras.size() << " train + " << s.test_cameras.size() << " test cameras, " << s.images
              << " images (" << s.images_kept << " kept from an interrupted run)\n";
  });
}
#endif

}  // namespace

void add_dataset_command(CLI::App& app) {
  auto* dataset = app.add_subcommand("dataset", "Build and inspect subject datasets (docs/layouts.md#dataset).");
  dataset->require_subcommand(1);
  add_check_command(*dataset);
#ifdef TEGA_HAVE_MATTING
  add_build_command(*dataset);
#endif
}

}  // namespace tega::cli
