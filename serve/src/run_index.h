#pragma once
// The JSON index of one served run that the page starts from.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include <string>
#include <vector>

#include "tega/core/dataset.h"
#include "tega/serve/frame_stream.h"

namespace tega::serve {

// Cameras (intrinsics, world_to_camera, image size, split), takes (the
// dataset's frames grouped by sequence, in order, each with its split),
// `fps`, the stream's counts, and the eval numbers of `eval_json` (its
// means per model and split) when that file exists.
// `mesh_takes`: further takes of mesh files, their frames of split "meshes" (no captured images).
struct MeshTake {
  std::string name;
  std::vector<std::string> frames;
};
nlohmann::json run_index(const std::string& run_id, const Dataset& dataset, const StaticPart& static_part,
                         double fps, const std::filesystem::path& eval_json, const std::vector<MeshTake>& mesh_takes);

}  // namespace tega::serve
