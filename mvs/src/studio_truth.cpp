#include "tega/mvs/studio_truth.h"

#include <Eigen/Geometry>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::mvs {
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

}  // namespace

StudioTruth load_studio_truth(const std::filesystem::path& capture, const std::string& take, int frame) {
  const auto head_dir = capture / "ground_truth" / "head";
  const auto head_file = head_dir / "head.json";
  nlohmann::json head;
  try {
    head = nlohmann::json::parse(read_text_file(head_file));
  } catch (const nlohmann::json::exception& e) {
    throw Error(head_file, std::string("is not valid JSON: ") + e.what());
  }
  const Mesh coarse = read_obj(head_dir / "template.obj");
  StudioTruth truth;
  truth.fine = read_obj(head_dir / "fine_topology.obj");
  char name[32];
  std::snprintf(name, sizeof name, "%06d.bin", frame);
  truth.fine.positions = read_vertices_bin(capture / "ground_truth" / take / "fine" / name, truth.fine.num_vertices());

  // Subdivision emits each coarse triangle's fine triangles as one run, in order.
  const std::vector<bool> region = coarse_face_region(coarse, head);
  const int run = coarse.num_faces() > 0 ? truth.fine.num_faces() / coarse.num_faces() : 0;
  if (run == 0 || run * coarse.num_faces() != truth.fine.num_faces())
    throw Error(head_dir / "fine_topology.obj", "does not subdivide template.obj (" +
                                                   std::to_string(truth.fine.num_faces()) + " triangles for " +
                                                   std::to_string(coarse.num_faces()) + ")");
  for (int f = 0; f < truth.fine.num_faces(); ++f)
    if (region[size_t(f / run)]) truth.face_region.push_back(f);
  std::vector<char> in_region(size_t(coarse.num_vertices()), 0);
  for (int f = 0; f < coarse.num_faces(); ++f)
    if (region[size_t(f)])
      for (int k = 0; k < 3; ++k) in_region[size_t(coarse.faces(f, k))] = 1;
  for (int v = 0; v < coarse.num_vertices(); ++v)
    if (in_region[size_t(v)]) truth.face_vertices.push_back(v);
  return truth;
}

}  // namespace tega::mvs
