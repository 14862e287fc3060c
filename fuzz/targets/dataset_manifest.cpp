#include "fuzz_target.h"
#include "tega/core/dataset.h"
#include "tiny_inputs.h"

namespace {

// A valid rig (cam00, cam01) and template beside the fuzzed manifest, written
// once per process; the seeds (seeds/write_seeds.cpp) name them.
std::filesystem::path dataset_folder_with_rig_and_template() {
  static const std::filesystem::path root = [] {
    const auto folder = tega::fuzz::scratch_folder() / "dataset";
    std::filesystem::create_directories(folder);
    tega::write_rig_json(tega::fuzz::tiny_rig(2, false), folder / "rig.json");
    tega::write_obj(tega::fuzz::tiny_mesh(), folder / "template.obj");
    return folder;
  }();
  return root;
}

}  // namespace

// The dataset manifest (dataset.json: frames, head poses, the train/test split).
TEGA_FUZZ_TARGET(dataset_manifest) {
  const auto root = dataset_folder_with_rig_and_template();
  tega::fuzz::input_file("dataset/dataset.json", data, size);
  tega::read_dataset(root);
}
