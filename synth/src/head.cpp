#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>

#include "tega/core/error.h"
#include "tega/synth/head.h"

namespace tega::synth {
namespace {

// ICT-FaceKit's polygon ranges (its README): the two eyeballs, and the
// lacrimal fluid, eye blend and eye occlusion meshes, which are see-through
// overlays that an opaque renderer must leave out.
constexpr int kIctVertices = 26719;
constexpr int kIctEyeballFirst = 21496, kIctEyeballLast = 24691;
constexpr int kIctOverlayFirst = 24692, kIctOverlayLast = 25303;

int polygon_of(const Mesh& mesh, int triangle) {
  return mesh.triangle_polygon.empty() ? triangle : mesh.triangle_polygon[triangle];
}

// Removes the triangles of polygons [first, last] and the vertices only they
// used; returns the kept vertices' old indices.
std::vector<int> remove_polygons(BlendshapeModel& model, int first, int last) {
  Mesh& m = model.neutral;
  std::vector<int> kept_faces;
  for (int f = 0; f < m.num_faces(); ++f) {
    const int p = polygon_of(m, f);
    if (p < first || p > last) kept_faces.push_back(f);
  }
  std::vector<int> new_index(m.num_vertices(), -1);
  for (int f : kept_faces)
    for (int k = 0; k < 3; ++k) new_index[m.faces(f, k)] = 0;
  std::vector<int> kept_vertices;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (new_index[v] == 0) new_index[v] = static_cast<int>(kept_vertices.size()), kept_vertices.push_back(v);

  const auto compact = [&](const Vertices& all) {
    Vertices out(kept_vertices.size(), 3);
    for (size_t i = 0; i < kept_vertices.size(); ++i) out.row(i) = all.row(kept_vertices[i]);
    return out;
  };
  Mesh out;
  out.positions = compact(m.positions);
  out.uvs = m.uvs;
  out.faces.resize(kept_faces.size(), 3);
  if (m.has_uvs()) out.uv_faces.resize(kept_faces.size(), 3);
  for (size_t i = 0; i < kept_faces.size(); ++i) {
    for (int k = 0; k < 3; ++k) out.faces(i, k) = new_index[m.faces(kept_faces[i], k)];
    if (m.has_uvs()) out.uv_faces.row(i) = m.uv_faces.row(kept_faces[i]);
    out.triangle_polygon.push_back(polygon_of(m, kept_faces[i]));
  }
  for (auto& d : model.identity_deltas) d = compact(d);
  for (auto& d : model.expression_deltas) d = compact(d);
  m = std::move(out);
  return kept_vertices;
}

std::vector<std::pair<int, int>> runs_of(const std::vector<int>& sorted) {
  std::vector<std::pair<int, int>> runs;
  for (int v : sorted) {
    if (!runs.empty() && runs.back().second + 1 == v)
      runs.back().second = v;
    else
      runs.emplace_back(v, v);
  }
  return runs;
}

Eigen::Vector3d centroid(const Mesh& mesh, const std::vector<int>& vertices) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v : vertices) sum += mesh.positions.row(v).cast<double>().transpose();
  return sum / std::max<size_t>(1, vertices.size());
}

// idx_to_landmark_verts of the model's vertex_indices.json, renumbered by
// the vertices the studio kept; empty where the file or the list is absent.
std::vector<int32_t> landmark_vertices(const std::filesystem::path& directory, const Head& head) {
  const std::filesystem::path file = directory / "vertex_indices.json";
  std::ifstream in(file);
  if (!in) return {};
  nlohmann::json indices;
  try {
    indices = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not valid JSON: ") + e.what());
  }
  if (!indices.contains("idx_to_landmark_verts")) return {};
  std::vector<int> kept;  // the model's index of each studio vertex
  for (const auto& [first, last] : head.source_vertex_runs)
    for (int v = first; v <= last; ++v) kept.push_back(v);
  std::vector<int32_t> out;
  for (const int model_vertex : indices.at("idx_to_landmark_verts").get<std::vector<int>>()) {
    int studio_vertex = model_vertex;
    if (!kept.empty()) {
      const auto found = std::lower_bound(kept.begin(), kept.end(), model_vertex);
      if (found == kept.end() || *found != model_vertex)
        throw Error(file, "landmark vertex " + std::to_string(model_vertex) + " is not on the studio's head");
      studio_vertex = int(found - kept.begin());
    }
    if (studio_vertex < 0 || studio_vertex >= head.model.num_vertices())
      throw Error(file, "landmark vertex " + std::to_string(model_vertex) + " is out of range");
    out.push_back(studio_vertex);
  }
  return out;
}

}  // namespace

Head load_head(const std::filesystem::path& directory, double metres_per_unit,
               const std::vector<int>& eyeball_polygons) {
  Head head;
  head.source = directory.string();
  head.model = BlendshapeModel::load_directory(directory, metres_per_unit);
  int first = 0, last = 0;
  if (eyeball_polygons.empty()) {
    if (head.model.num_vertices() != kIctVertices)
      throw Error(directory, "which polygons are the eyeballs is unknown for this model (" +
                                 std::to_string(head.model.num_vertices()) +
                                 " vertices, not ICT-FaceKit's topology): set head_eyeball_polygons");
    // The overlays lie after the eyeballs, so removing them keeps the eyeball range.
    head.source_vertex_runs = runs_of(remove_polygons(head.model, kIctOverlayFirst, kIctOverlayLast));
    first = kIctEyeballFirst;
    last = kIctEyeballLast;
  } else if (eyeball_polygons.size() == 2 && eyeball_polygons[0] <= eyeball_polygons[1]) {
    first = eyeball_polygons[0];
    last = eyeball_polygons[1];
  } else {
    throw Error(directory, "head_eyeball_polygons must be [first, last] with first <= last");
  }
  const Mesh& m = head.model.neutral;
  for (int f = 0; f < m.num_faces(); ++f) {
    const int p = polygon_of(m, f);
    if (p >= first && p <= last) head.eyeball_faces.push_back(f);
  }
  if (head.eyeball_faces.empty())
    throw Error(directory, "no triangle lies in the eyeball polygons [" + std::to_string(first) + ", " +
                               std::to_string(last) + "]");
  head.landmark_vertices = landmark_vertices(directory, head);
  finish_head(head);
  return head;
}

void finish_head(Head& head) {
  const Mesh& m = head.model.neutral;
  // The eyeball vertices split into two eyes by their side of the mean.
  std::vector<char> is_eye_vertex(m.num_vertices(), 0);
  for (int f : head.eyeball_faces)
    for (int k = 0; k < 3; ++k) is_eye_vertex[m.faces(f, k)] = 1;
  std::vector<int> eye_vertices;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (is_eye_vertex[v]) eye_vertices.push_back(v);
  const double mid_x = centroid(m, eye_vertices).x();
  std::vector<int> left, right;
  for (int v : eye_vertices) (m.positions(v, 0) > mid_x ? left : right).push_back(v);

  FaceFrame& frame = head.frame;
  frame.eye_left = centroid(m, left);
  frame.eye_right = centroid(m, right);
  frame.origin = 0.5 * (frame.eye_left + frame.eye_right);
  frame.interocular = (frame.eye_left - frame.eye_right).norm();
  const Eigen::Vector3d right_axis = (frame.eye_left - frame.eye_right).normalized();
  const Eigen::Vector3d up = (Eigen::Vector3d::UnitY() - right_axis.y() * right_axis).normalized();
  frame.axes.col(0) = right_axis;
  frame.axes.col(1) = up;
  frame.axes.col(2) = right_axis.cross(up);

  head.triangle_eye.assign(m.num_faces(), 0);
  for (int f : head.eyeball_faces) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += m.positions.row(m.faces(f, k)).cast<double>().transpose() / 3.0;
    head.triangle_eye[f] = (c - frame.eye_left).norm() < (c - frame.eye_right).norm() ? 1 : 2;
  }

  // The rigid motion turns the head about a point near its centre: below
  // and behind the eyes.
  head.pivot = frame.origin + frame.axes * Eigen::Vector3d(0, -0.6, -1.2) * frame.interocular;

  WrinkleRegion forehead;
  forehead.name = "forehead";
  forehead.drivers = {"browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R", "browInnerUp"};
  forehead.centre = {0, 0.8};
  forehead.sigma = {0.55, 0.22};
  forehead.period = 0.17;
  head.wrinkles = {forehead};
  for (const auto& [suffix, side] : {std::pair{"_L", 1.0}, std::pair{"_R", -1.0}}) {
    // Nasolabial folds run from the nose wing down and out past the mouth corner.
    WrinkleRegion fold;
    fold.name = std::string("nasolabial") + suffix;
    fold.drivers = {std::string("mouthSmile") + suffix};
    fold.centre = {side * 0.55, -0.75};
    fold.sigma = {0.35, 0.1};
    fold.angle = std::atan2(-0.65, side * 0.2);
    fold.groove_width = 0.05;
    fold.darkening_scale = 0.8;
    head.wrinkles.push_back(fold);
  }
}

}  // namespace tega::synth
