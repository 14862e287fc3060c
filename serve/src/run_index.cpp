#include "run_index.h"

#include <algorithm>

#include "tega/core/json_file.h"

namespace tega::serve {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string split_of(const std::vector<std::string>& train, const std::vector<std::string>& test,
                     const std::string& name) {
  if (std::find(train.begin(), train.end(), name) != train.end()) return "train";
  if (std::find(test.begin(), test.end(), name) != test.end()) return "test";
  return "none";
}

json camera_json(const Camera& c, const Dataset& dataset) {
  const Eigen::Matrix3d& r = c.world_to_camera.R;
  return {{"name", c.name},
          {"width", c.width},
          {"height", c.height},
          {"fx", c.K(0, 0)},
          {"fy", c.K(1, 1)},
          {"cx", c.K(0, 2)},
          {"cy", c.K(1, 2)},
          {"rotation", {r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)}},
          {"translation", {c.world_to_camera.t.x(), c.world_to_camera.t.y(), c.world_to_camera.t.z()}},
          {"split", split_of(dataset.train.cameras, dataset.test.cameras, c.name)}};
}

// eval.json without its per-view, per-camera and per-frame lists: what the page shows.
json eval_summary(const fs::path& eval_json) {
  if (!fs::is_regular_file(eval_json)) return nullptr;
  const json doc = read_json_file(eval_json);
  json models = json::array();
  const json listed = doc.value("models", json::array());
  for (const json& model : listed) {
    json splits = json::object();
    const json evaluated = model.value("splits", json::object());  // items() must not outlive it
    for (const auto& [name, split] : evaluated.items())
      splits[name] = {{"views", split.value("views", 0)}, {"metrics", split.value("metrics", json::object())}};
    models.push_back({{"name", model.value("name", "")}, {"iteration", model.value("iteration", 0)},
                      {"splits", splits}});
  }
  return {{"file", eval_json.string()}, {"models", models}};
}

}  // namespace

json run_index(const std::string& run_id, const Dataset& dataset, const StaticPart& static_part, double fps,
               const fs::path& eval_json, const std::vector<MeshTake>& mesh_takes) {
  json cameras = json::array();
  for (const Camera& c : dataset.rig.cameras) cameras.push_back(camera_json(c, dataset));
  json takes = json::array();
  for (const DatasetFrame& f : dataset.frames) {
    if (takes.empty() || takes.back()["name"] != f.sequence) takes.push_back({{"name", f.sequence}, {"frames", json::array()}});
    takes.back()["frames"].push_back({{"id", f.id}, {"split", split_of(dataset.train.frames, dataset.test.frames, f.id)}});
  }
  for (const MeshTake& take : mesh_takes) {
    json frames = json::array();
    for (const std::string& id : take.frames) frames.push_back({{"id", id}, {"split", "meshes"}});
    takes.push_back({{"name", take.name}, {"frames", frames}});
  }
  const std::string base = "/api/runs/" + run_id;
  return {{"format", "tega-serve-index"},
          {"version", kStreamVersion},
          {"run", run_id},
          {"fps", fps},
          {"gaussians", static_part.size()},
          {"sh_degree", static_part.sh_degree},
          {"antialiased", static_part.antialiased},
          {"background", static_part.background},
          {"cameras", cameras},
          {"takes", takes},
          {"eval", eval_summary(eval_json)},
          {"urls",
           {{"static", base + "/static.bin"},
            {"frame", base + "/frames/{frame}.bin"},
            {"image", base + "/images/{camera}/{frame}.png"}}}};
}

}  // namespace tega::serve
