#include "tega/scoring/studio_landmarks.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/json_file.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

std::string frame_name(int frame) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d", frame);
  return name;
}

// frame -> the rotation of its head_to_world (a take's frames.json).
std::map<int, Eigen::Matrix3d> head_rotations(const fs::path& frames_file) {
  const nlohmann::json frames = read_json_file(frames_file);
  std::map<int, Eigen::Matrix3d> rotations;
  try {
    for (const auto& frame : frames.at("frames")) {
      Eigen::Matrix3d R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = frame.at("head_to_world").at(r).at(c).get<double>();
      rotations[frame.at("index").get<int>()] = R;
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(frames_file, std::string("has no head_to_world per frame: ") + e.what());
  }
  return rotations;
}

}  // namespace

std::vector<int> model_landmark_vertices(const fs::path& model_directory) {
  const fs::path file = model_directory / "vertex_indices.json";
  if (!fs::exists(file)) throw Error(file, "not found: the model's landmark vertices (idx_to_landmark_verts)");
  const nlohmann::json indices = read_json_file(file);
  if (!indices.contains("idx_to_landmark_verts")) throw Error(file, "has no idx_to_landmark_verts");
  const auto vertices = indices.at("idx_to_landmark_verts").get<std::vector<int>>();
  if (vertices.size() != landmarks::kLandmarkCount)
    throw Error(file, "idx_to_landmark_verts lists " + std::to_string(vertices.size()) + " vertices, not " +
                          std::to_string(landmarks::kLandmarkCount));
  return vertices;
}

StudioLandmarkTruth::StudioLandmarkTruth(const fs::path& capture, const std::vector<int>& landmark_vertices)
    : truth_(studio_truth_root(capture)), rig_(read_rig_json(truth_ / "rig.json")) {
  template_ = read_obj(truth_ / "ground_truth" / "head" / "template.obj");
  const std::vector<int> model_vertex = studio_model_vertices(truth_);
  for (const int model_index : landmark_vertices) {
    const auto found = std::find(model_vertex.begin(), model_vertex.end(), model_index);
    if (found == model_vertex.end())
      throw Error(studio_head_json(truth_),
                  "the studio's head has no vertex " + std::to_string(model_index) + " of the model");
    studio_landmark_vertices_.push_back(int(found - model_vertex.begin()));
  }
  for (const CaptureTake& take : read_capture(capture).takes) {
    if (take.kind != "performance") continue;
    takes_[take.name] = read_take(capture / "takes" / take.name);
    head_rotations_[take.name] = head_rotations(truth_ / "ground_truth" / take.name / "frames.json");
  }
}

StudioFrameLandmarks StudioLandmarkTruth::frame(const std::string& take, int frame) const {
  const auto rotations = head_rotations_.find(take);
  if (rotations == head_rotations_.end())
    throw Error(truth_ / "ground_truth" / take, "is not a performance take of the studio");
  if (!rotations->second.count(frame))
    throw Error(truth_ / "ground_truth" / take / "frames.json", "has no frame " + std::to_string(frame));
  Mesh mesh = template_;
  mesh.positions = read_vertices_bin(truth_ / "ground_truth" / take / "coarse" / (frame_name(frame) + ".bin"),
                                     template_.num_vertices());
  const Vertices normals = mesh.vertex_normals();
  StudioFrameLandmarks landmarks{take, frame, {}, {}, rotations->second.at(frame).col(2), Eigen::Vector3d::Zero()};
  for (const int vertex : studio_landmark_vertices_) {
    landmarks.positions.push_back(mesh.positions.row(vertex).cast<double>());
    landmarks.normals.push_back(normals.row(vertex).cast<double>());
    landmarks.centre += landmarks.positions.back() / double(studio_landmark_vertices_.size());
  }
  return landmarks;
}

double StudioLandmarkTruth::view_angle_deg(const StudioFrameLandmarks& frame, const std::string& camera) const {
  const Eigen::Vector3d to_camera = (rig_.camera(camera).center() - frame.centre).normalized();
  return std::acos(std::clamp(to_camera.dot(frame.face_front), -1.0, 1.0)) * 180 / M_PI;
}

landmarks::LandmarkSample StudioLandmarkTruth::sample(const StudioFrameLandmarks& frame, const std::string& camera_name) const {
  const Camera& camera = rig_.camera(camera_name);
  landmarks::LandmarkSample sample;
  sample.image = read_image_u8(takes_.at(frame.take).image_path(camera_name, frame.frame));
  for (size_t i = 0; i < frame.positions.size(); ++i) {
    const Eigen::Vector2d pixel = camera.project(frame.positions[i]).value();
    sample.box.extend(pixel);
    const bool facing = frame.normals[i].dot(camera.center() - frame.positions[i]) > 0;
    sample.landmarks.push_back(facing ? pixel : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  sample.box = grown_landmark_box(sample.box);
  return sample;
}

landmarks::LandmarkSample studio_landmark_sample(const fs::path& capture, const std::string& take, const std::string& camera,
                                      int frame, const std::vector<int>& landmark_vertices) {
  const StudioLandmarkTruth truth(capture, landmark_vertices);
  return truth.sample(truth.frame(take, frame), camera);
}

}  // namespace tega::scoring
