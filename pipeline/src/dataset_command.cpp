#include <iostream>
#include <map>
#include <memory>

#include "commands.h"
#include "tega/core/dataset.h"
#include "tega/core/dataset_gaps.h"

#ifdef TEGA_HAVE_MATTING
#include "stage_options.h"
#include "tega/matting/dataset_build.h"
#endif

namespace tega::cli {

namespace {

// The images and frames the dataset's producer left out, counted per camera
// and per frame, then each with its reason.
void print_gaps(const Dataset& d) {
  const std::string summary = dataset_gap_summary(d);
  if (summary.empty()) return;
  std::cout << "gaps (training and evaluation skip them): " << summary << "\n";
  if (!d.missing_images.empty()) {
    std::map<std::string, int> per_frame;
    for (const auto& m : d.missing_images) ++per_frame[m.frame];
    std::cout << "  missing images per frame:";
    for (const auto& [frame, n] : per_frame) std::cout << " " << frame << ": " << n;
    std::cout << "\n";
    for (const auto& m : d.missing_images)
      std::cout << "  missing image: camera " << m.camera << ", frame " << m.frame << ": " << m.reason << "\n";
  }
  for (const auto& f : d.dropped_frames) std::cout << "  dropped frame " << f.frame << ": " << f.reason << "\n";
}

void add_check_command(CLI::App& dataset) {
  auto* check = dataset.add_subcommand(
      "check", "Check a dataset the way training does before it starts: manifest, rig, template, split, "
               "every image (exists, size, RGBA) and every mesh (vertex count). Exits non-zero naming "
               "the first offending file. Reports the images and frames the dataset's producer left out "
               "(missing_images, dropped_frames), per camera and per frame.");
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
    print_gaps(d);
  });
}

#ifdef TEGA_HAVE_MATTING
struct BuildArguments {
  matting::DatasetBuildRequest request;
  StageOptionFlags options;
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
  build->add_flag("--force", args->request.replace_existing, "Replace --out if it already exists.");
  args->options.add_to(*build, "dataset", "dataset", "frames=100");
  build->callback([args] {
    const auto options = args->options.load<matting::DatasetBuildOptions>();
    if (args->options.print_if_asked(options)) return;
    const auto& r = args->request;
    if (r.capture.empty() || r.tracked.empty() || r.out.empty())
      throw Error("tega dataset build: --capture, --tracked and --out are required");
    const auto s = matting::build_dataset(r, options);
    std::cout << s.dataset.string() << ": " << s.train_frames << " train + " << s.test_frames << " test frames, "
              << s.train_cameras.size() << " train + " << s.test_cameras.size() << " test cameras, " << s.images
              << " images (" << s.images_kept << " kept from an interrupted run)";
    if (s.missing_images > 0 || s.dropped_frames > 0)
      std::cout << "; left out: " << s.missing_images << " missing or unreadable images, " << s.dropped_frames
                << " frames with too few cameras (dataset.json: missing_images, dropped_frames)";
    std::cout << "\n";
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
