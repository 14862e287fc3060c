#include "tega/scoring/studio_truth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/json_file.h"
#include "tega/core/rig.h"
#include "tega/core/thread_pool.h"
#include "tega/synth/ground_truth_depth.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

std::vector<bool> coarse_face_region(const Mesh& coarse, const nlohmann::json& head) {
  const auto eye = [&](const char* key) {
    const auto& v = head.at(key);
    return Eigen::Vector3d(v.at(0), v.at(1), v.at(2));
  };
  const Eigen::Vector3d origin = 0.5 * (eye("eye_left") + eye("eye_right"));
  const double unit = head.at("interocular_m");
  std::vector<bool> inside(size_t(coarse.num_faces()));
  for (int f = 0; f < coarse.num_faces(); ++f) {
    const Eigen::Vector3d a = coarse.positions.row(coarse.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = coarse.positions.row(coarse.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = coarse.positions.row(coarse.faces(f, 2)).cast<double>();
    const Eigen::Vector3d centre = ((a + b + c) / 3.0 - origin) / unit;
    const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
    inside[size_t(f)] = std::abs(centre.x()) <= 1.1 && centre.y() >= -1.9 && centre.y() <= 1.1 && centre.z() >= -0.9 &&
                        normal.z() > 0.1;
  }
  return inside;
}

// How many of the rig's cameras see each listed face's centroid: in the
// image, facing the camera, and no more than kDepthTolerance behind the
// nearest surface there. Depth is rendered at most kMaxSide pixels wide:
// enough to tell a face from the lips or eyelids that hide it. The cameras
// render on threads of their own: a 3072 x 2048 studio's fine head took 2 s
// a frame with them one after the other.
std::vector<int> cameras_seeing(const Mesh& mesh, const std::vector<int>& faces, const Rig& rig) {
  constexpr double kDepthTolerance = 0.002, kMaxSide = 1024;
  std::vector<std::vector<char>> seen_by(rig.cameras.size(), std::vector<char>(faces.size(), 0));
  ThreadPool pool(std::min<int>(default_thread_count(), int(rig.cameras.size())));
  pool.parallel_for(0, int64_t(rig.cameras.size()), [&](int64_t k) {
    const Camera& full = rig.cameras[size_t(k)];
    std::vector<char>& seen = seen_by[size_t(k)];
    Camera camera = full.scaled(std::min(1.0, kMaxSide / std::max(full.width, full.height)));
    camera.distortion = {};
    const ImageF depth = synth::render_depth(camera, mesh.positions, mesh.faces);
    const Eigen::Vector3d centre = camera.center();
    for (size_t i = 0; i < faces.size(); ++i) {
      const int f = faces[i];
      const Eigen::Vector3d a = mesh.positions.row(mesh.faces(f, 0)).cast<double>();
      const Eigen::Vector3d b = mesh.positions.row(mesh.faces(f, 1)).cast<double>();
      const Eigen::Vector3d c = mesh.positions.row(mesh.faces(f, 2)).cast<double>();
      const Eigen::Vector3d point = (a + b + c) / 3.0;
      if ((b - a).cross(c - a).dot(centre - point) <= 0) continue;
      const auto pixel = camera.project(point);
      if (!pixel) continue;
      const int x = int(std::lround(pixel->x())), y = int(std::lround(pixel->y()));
      if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) continue;
      const float nearest = depth.at(x, y, 0);
      const double z = camera.world_to_camera.apply(point).z();
      if (nearest > 0 && z <= nearest + kDepthTolerance) seen[i] = 1;
    }
  });
  std::vector<int> seen(faces.size(), 0);
  for (const std::vector<char>& by_camera : seen_by)
    for (size_t i = 0; i < faces.size(); ++i) seen[i] += by_camera[i];
  return seen;
}

}  // namespace

StudioTruthSource::StudioTruthSource(const std::filesystem::path& capture)
    : capture_(capture), rig_(read_rig_json(capture / "rig.json")) {
  const auto head_dir = capture / "ground_truth" / "head";
  const auto head_file = head_dir / "head.json";
  nlohmann::json head;
  try {
    head = nlohmann::json::parse(read_text_file(head_file));
  } catch (const nlohmann::json::exception& e) {
    throw Error(head_file, std::string("is not valid JSON: ") + e.what());
  }
  coarse_ = read_obj(head_dir / "template.obj");
  fine_ = read_obj(head_dir / "fine_topology.obj");
  // Subdivision emits each coarse triangle's fine triangles as one run, in order.
  run_ = coarse_.num_faces() > 0 ? fine_.num_faces() / coarse_.num_faces() : 0;
  if (run_ == 0 || run_ * coarse_.num_faces() != fine_.num_faces())
    throw Error(head_dir / "fine_topology.obj", "does not subdivide template.obj (" +
                                                   std::to_string(fine_.num_faces()) + " triangles for " +
                                                   std::to_string(coarse_.num_faces()) + ")");
  const std::vector<bool> region = coarse_face_region(coarse_, head);
  for (int f = 0; f < fine_.num_faces(); ++f)
    if (region[size_t(f / run_)]) box_.push_back(f);
}

StudioTruth StudioTruthSource::frame(const std::string& take, int frame) const {
  StudioTruth truth;
  truth.fine = fine_;
  char name[32];
  std::snprintf(name, sizeof name, "%06d.bin", frame);
  truth.fine.positions = read_vertices_bin(capture_ / "ground_truth" / take / "fine" / name, fine_.num_vertices());
  // The box also holds what no camera can see (a closed mouth's teeth and
  // socket, the eye sockets behind the eyeballs): stereo needs two views.
  const std::vector<int> seen = cameras_seeing(truth.fine, box_, rig_);
  for (size_t i = 0; i < box_.size(); ++i)
    if (seen[i] >= 2) truth.face_region.push_back(box_[i]);
  // A coarse triangle is seen where most of its fine ones are.
  std::vector<int> seen_fine(size_t(coarse_.num_faces()), 0);
  for (int f : truth.face_region) ++seen_fine[size_t(f / run_)];
  std::vector<char> in_region(size_t(coarse_.num_vertices()), 0);
  for (int f = 0; f < coarse_.num_faces(); ++f)
    if (2 * seen_fine[size_t(f)] > run_)
      for (int k = 0; k < 3; ++k) in_region[size_t(coarse_.faces(f, k))] = 1;
  for (int v = 0; v < coarse_.num_vertices(); ++v)
    if (in_region[size_t(v)]) truth.face_vertices.push_back(v);
  return truth;
}

StudioTruth load_studio_truth(const std::filesystem::path& capture, const std::string& take, int frame) {
  return StudioTruthSource(capture).frame(take, frame);
}

fs::path studio_head_json(const fs::path& truth) { return truth / "ground_truth" / "head" / "head.json"; }

fs::path studio_truth_root(const fs::path& capture) {
  if (fs::exists(studio_head_json(capture))) return capture;
  fs::path truth = capture;
  if (!truth.has_filename()) truth = truth.parent_path();  // "capture/" names capture
  truth += ".truth";
  if (fs::exists(studio_head_json(truth))) return truth;
  throw Error(studio_head_json(capture), "not found: not a virtual-studio capture with its ground truth (nor is " +
                                      truth.string() + "/ beside it)");
}

std::vector<int> studio_model_vertices(const fs::path& capture) {
  const int studio_vertices = read_obj(capture / "ground_truth" / "head" / "template.obj").num_vertices();
  const fs::path file = studio_head_json(capture);
  const auto head = read_json_file(file);
  std::vector<int> model_vertex;
  for (const auto& run : head.value("source_vertex_runs", nlohmann::json::array()))
    for (int v = run.at(0).get<int>(); v <= run.at(1).get<int>(); ++v) model_vertex.push_back(v);
  if (model_vertex.empty())
    for (int v = 0; v < studio_vertices; ++v) model_vertex.push_back(v);
  if (int(model_vertex.size()) != studio_vertices)
    throw Error(file, "source_vertex_runs cover " + std::to_string(model_vertex.size()) +
                          " vertices; template.obj has " + std::to_string(studio_vertices));
  return model_vertex;
}

fs::path studio_head_model(const fs::path& capture) {
  const fs::path file = studio_head_json(studio_truth_root(capture));
  const std::string source = read_json_file(file).value("source", "");
  if (source.empty() || source == "procedural")
    throw Error(file, "the studio rendered its procedural head, which has no landmark vertices: render a model "
                      "laid out like ICT-FaceKit (tega synth --head DIR)");
  if (!fs::is_directory(source))
    throw Error(file, "its head model " + source + " is not a directory here: name the model directory");
  return source;
}

}  // namespace tega::scoring
