#include <iostream>
#include <memory>

#include "commands.h"
#include "tega/core/dataset.h"

namespace tega::cli {

void add_dataset_command(CLI::App& app) {
  auto* dataset = app.add_subcommand("dataset", "Inspect subject datasets (docs/layouts.md#dataset).");
  dataset->require_subcommand(1);

  auto* check = dataset->add_subcommand(
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

}  // namespace tega::cli
