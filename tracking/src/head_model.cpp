#include "tega/tracking/head_model.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::tracking {
namespace {

// ICT-FaceKit's vertex ranges (its README), used when vertex_indices.json
// does not name the sets: eyeballs, and the face, head and neck skin.
constexpr int kIctVertices = 26719;
const std::vector<int> kIctEyeballRanges = {21451, 24590};
const std::vector<int> kIctSkinRanges = {0, 11247};
constexpr double kPoseVertexMotionM = 0.001;

std::vector<int> expand_ranges(const std::vector<int>& ranges, const std::filesystem::path& file, const char* key) {
  if (ranges.size() % 2 != 0) throw Error(file, std::string(key) + " must list [first, last] pairs");
  std::vector<int> vertices;
  for (size_t i = 0; i < ranges.size(); i += 2) {
    if (ranges[i] > ranges[i + 1]) throw Error(file, std::string(key) + ": a range ends before it starts");
    for (int v = ranges[i]; v <= ranges[i + 1]; ++v) vertices.push_back(v);
  }
  return vertices;
}

std::vector<int> index_set(const nlohmann::json& indices, const char* key, const std::filesystem::path& file) {
  if (!indices.contains(key)) return {};
  return indices.at(key).get<std::vector<int>>();
}

void check_in_range(const std::vector<int>& vertices, int count, const std::filesystem::path& file, const char* what) {
  for (int v : vertices)
    if (v < 0 || v >= count)
      throw Error(file, std::string(what) + " names vertex " + std::to_string(v) + " but the model has " +
                            std::to_string(count) + " vertices");
}

}  // namespace

std::vector<int> HeadModel::fit_vertices_every(int step) const {
  std::vector<int> every;
  for (size_t i = 0; i < fit_vertices.size(); i += size_t(std::max(1, step))) every.push_back(fit_vertices[i]);
  return every;
}

HeadModel load_head_model(const std::filesystem::path& directory, double metres_per_unit) {
  HeadModel model;
  model.directory = directory;
  model.shapes = BlendshapeModel::load_directory(directory, metres_per_unit);
  const int count = model.num_vertices();
  const auto file = directory / "vertex_indices.json";
  if (!std::filesystem::exists(file))
    throw Error(file, "is missing: the model's vertex sets (idx_to_fitting_verts, idx_to_landmark_verts, ...) "
                      "are needed to track it");
  nlohmann::json indices;
  try {
    indices = nlohmann::json::parse(read_text_file(file));
    model.fit_vertices = index_set(indices, "idx_to_fitting_verts", file);
    model.landmark_vertices = index_set(indices, "idx_to_landmark_verts", file);
    const bool ict = count == kIctVertices;
    const auto ranges = [&](const char* key, const std::vector<int>& ict_ranges) {
      if (indices.contains(key)) return expand_ranges(indices.at(key).get<std::vector<int>>(), file, key);
      if (ict) return expand_ranges(ict_ranges, file, key);
      throw Error(file, std::string("has no ") + key + " and the model is not ICT-FaceKit's topology (" +
                            std::to_string(count) + " vertices)");
    };
    model.eyeball_vertices = ranges("eyeball_vertex_ranges", kIctEyeballRanges);
    model.skin_vertices = ranges("skin_vertex_ranges", kIctSkinRanges);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid index file: ") + e.what());
  }
  if (model.fit_vertices.empty()) throw Error(file, "idx_to_fitting_verts is missing or empty");
  if (!model.landmark_vertices.empty() && model.landmark_vertices.size() != 68)
    throw Error(file, "idx_to_landmark_verts has " + std::to_string(model.landmark_vertices.size()) +
                          " vertices; tracking uses the 68 Multi-PIE landmarks");
  check_in_range(model.fit_vertices, count, file, "idx_to_fitting_verts");
  check_in_range(model.landmark_vertices, count, file, "idx_to_landmark_verts");
  check_in_range(model.eyeball_vertices, count, file, "eyeball_vertex_ranges");
  check_in_range(model.skin_vertices, count, file, "skin_vertex_ranges");

  // Eyeballs turn with the head only.
  for (auto& delta : model.shapes.expression_deltas)
    for (int v : model.eyeball_vertices) delta.row(v).setZero();
  std::vector<float> largest_motion(count, 0.f);
  for (const auto& delta : model.shapes.expression_deltas)
    for (int v = 0; v < count; ++v) largest_motion[v] = std::max(largest_motion[v], delta.row(v).norm());
  // Models whose every expression moves most of the face still get the
  // quarter of the fit vertices that moves least.
  std::vector<float> fit_motion;
  for (int v : model.fit_vertices) fit_motion.push_back(largest_motion[v]);
  std::nth_element(fit_motion.begin(), fit_motion.begin() + fit_motion.size() / 4, fit_motion.end());
  const float bound = std::max(float(kPoseVertexMotionM), fit_motion[fit_motion.size() / 4]);
  for (int v : model.fit_vertices)
    if (largest_motion[v] <= bound) model.pose_vertices.push_back(v);
  return model;
}

}  // namespace tega::tracking
