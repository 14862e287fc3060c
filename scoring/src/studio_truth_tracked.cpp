#include <nlohmann/json.hpp>
#include <set>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/take.h"
#include "tega/core/tracked.h"
#include "tega/scoring/tracking_scores.h"

namespace tega::scoring {
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
  TrackedSubject subject;
  subject.model = fs::absolute(head);
  subject.neutral = neutral;
  subject.eyeball_vertices.assign(eyeball.begin(), eyeball.end());
  write_tracked_subject(subject, out / "identity.json");

  for (const std::string& take : read_capture(capture).performance_takes(takes, "to write as tracked")) {
    const fs::path truth = capture / "ground_truth" / take;
    const auto frames = nlohmann::json::parse(read_text_file(truth / "frames.json")).at("frames");
    fs::create_directories(out / take);
    for (const auto& f : frames) {
      TrackedFrame record;
      record.frame = f.at("index");
      record.status = "tracked";
      const Vertices vertices = transformed(
          truth_to_world, read_vertices_bin(tracked_frame_file(truth / "coarse", record.frame, ".bin"), neutral.num_vertices()));
      Eigen::Matrix<double, 3, 4> head_to_truth;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) head_to_truth(r, c) = f.at("head_to_world").at(r).at(c);
      record.head_to_world = truth_to_world * RigidTransform::from_matrix(head_to_truth);
      record.expression = f.at("expression").get<std::map<std::string, double>>();
      record.residuals = {{"surface_median_mm", 0.0}, {"surface_p90_mm", 0.0}, {"inlier_fraction", 1.0}};
      write_tracked_frame(out / take, record, &vertices);
    }
    const nlohmann::json summary = {{"take", take},
                                    {"frames", frames.size()},
                                    {"tracked", frames.size()},
                                    {"frames_not_tracked", nlohmann::json::array()},
                                    {"source", "ground truth of the virtual studio"}};
    write_text_atomic(out / take / "track.json", summary.dump(2) + "\n");
  }
}

}  // namespace tega::scoring
