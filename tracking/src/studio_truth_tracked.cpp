#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/take.h"
#include "tega/tracking/evaluation.h"
#include "vertex_runs.h"

namespace tega::tracking {
namespace fs = std::filesystem;

void write_studio_truth_as_tracked(const fs::path& capture, const fs::path& out, const std::vector<std::string>& takes,
                                   const RigidTransform& truth_to_world) {
  if (fs::exists(out)) throw Error(out, "exists already");
  const fs::path head = capture / "ground_truth" / "head";
  const Mesh neutral = read_obj(head / "template.obj");
  const auto head_json = nlohmann::json::parse(read_text_file(head / "head.json"));
  std::set<int> eyeball;
  for (const auto& f : head_json.at("eyeball_faces"))
    for (int k = 0; k < 3; ++k) eyeball.insert(neutral.faces(f.get<int>(), k));

  fs::create_directories(out);
  write_obj(neutral, out / "identity_neutral.obj");
  const nlohmann::json identity = {{"model", fs::absolute(head).string()},
                                   {"model_vertices", neutral.num_vertices()},
                                   {"identity", nlohmann::json::object()},
                                   {"neutral", "identity_neutral.obj"},
                                   {"eyeball_vertex_runs", vertex_runs({eyeball.begin(), eyeball.end()})},
                                   {"landmark_vertices", nlohmann::json::array()}};
  write_text_atomic(out / "identity.json", identity.dump(2) + "\n");

  for (const std::string& take : read_capture(capture).performance_takes(takes, "to write as tracked")) {
    const fs::path truth = capture / "ground_truth" / take;
    const auto frames = nlohmann::json::parse(read_text_file(truth / "frames.json")).at("frames");
    fs::create_directories(out / take);
    for (const auto& f : frames) {
      const int frame = f.at("index");
      char name[16];
      std::snprintf(name, sizeof name, "%06d", frame);
      Vertices vertices = read_vertices_bin(truth / "coarse" / (std::string(name) + ".bin"), neutral.num_vertices());
      for (Eigen::Index v = 0; v < vertices.rows(); ++v)
        vertices.row(v) = truth_to_world.apply(vertices.row(v).transpose().cast<double>()).cast<float>().transpose();
      write_vertices_bin(vertices, out / take / (std::string(name) + ".bin"));
      Eigen::Matrix<double, 3, 4> head_to_truth;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) head_to_truth(r, c) = f.at("head_to_world").at(r).at(c);
      const Eigen::Matrix<double, 3, 4> head_to_world = (truth_to_world * RigidTransform::from_matrix(head_to_truth)).matrix();
      nlohmann::json pose = nlohmann::json::array();
      for (int r = 0; r < 3; ++r) pose.push_back({head_to_world(r, 0), head_to_world(r, 1), head_to_world(r, 2), head_to_world(r, 3)});
      const nlohmann::json record = {
          {"frame", frame},
          {"status", "tracked"},
          {"head_to_world", pose},
          {"expression", f.at("expression")},
          {"residuals", {{"surface_median_mm", 0.0}, {"surface_p90_mm", 0.0}, {"inlier_fraction", 1.0}}},
          {"mesh", std::string(name) + ".bin"}};
      write_text_atomic(out / take / (std::string(name) + ".json"), record.dump(2) + "\n");
    }
    const nlohmann::json summary = {{"take", take},
                                    {"frames", frames.size()},
                                    {"tracked", frames.size()},
                                    {"frames_not_tracked", nlohmann::json::array()},
                                    {"source", "ground truth of the virtual studio"}};
    write_text_atomic(out / take / "track.json", summary.dump(2) + "\n");
  }
}

}  // namespace tega::tracking
