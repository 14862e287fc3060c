#include "tega/tracking/tracked.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::tracking {
namespace fs = std::filesystem;

TrackedSubject read_tracked_subject(const fs::path& tracked) {
  const fs::path file = tracked / "identity.json";
  if (!fs::exists(file)) throw Error(file, "is missing: " + tracked.string() + " is not the output of tega track");
  TrackedSubject subject;
  fs::path mesh_file;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    subject.model = j.at("model").get<std::string>();
    mesh_file = tracked / j.at("neutral").get<std::string>();
    if (!j.contains("eyeball_vertex_runs"))
      throw Error(file, "was written by an older tega track (no eyeball_vertex_runs): track the subject again");
    for (const auto& run : j.at("eyeball_vertex_runs"))
      for (int v = run.at(0).get<int>(); v <= run.at(1).get<int>(); ++v) subject.eyeball_vertices.push_back(v);
    subject.landmark_vertices = j.at("landmark_vertices").get<std::vector<int>>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid identity file: ") + e.what());
  }
  subject.neutral = read_obj(mesh_file);
  const int count = subject.neutral.num_vertices();
  const auto out_of_range = [count](int v) { return v < 0 || v >= count; };
  if (std::any_of(subject.eyeball_vertices.begin(), subject.eyeball_vertices.end(), out_of_range) ||
      std::any_of(subject.landmark_vertices.begin(), subject.landmark_vertices.end(), out_of_range))
    throw Error(file, "names vertices beyond the " + std::to_string(count) + " of " + mesh_file.string());
  return subject;
}

TrackedFrame read_tracked_frame(const fs::path& file) {
  TrackedFrame f;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    f.frame = j.at("frame");
    f.status = j.at("status");
    f.reason = j.value("reason", "");
    if (f.status != "skipped") {
      Eigen::Matrix<double, 3, 4> m;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = j.at("head_to_world").at(r).at(c);
      f.head_to_world = RigidTransform::from_matrix(m);
      for (const auto& [name, value] : j.at("expression").items()) f.expression[name] = value.get<double>();
    }
    if (f.tracked()) f.mesh = file.parent_path() / j.at("mesh").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid frame record: ") + e.what());
  }
  return f;
}

std::vector<TrackedFrame> read_tracked_take(const fs::path& tracked, const std::string& take) {
  const fs::path dir = tracked / take;
  if (!fs::exists(dir / "track.json"))
    throw Error(dir / "track.json", "is missing: take " + take + " was not tracked to its end (run tega track)");
  std::vector<fs::path> records;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() == ".json" && stem.size() == 6 && std::all_of(stem.begin(), stem.end(), ::isdigit))
      records.push_back(entry.path());
  }
  std::sort(records.begin(), records.end());
  std::vector<TrackedFrame> frames;
  for (const fs::path& file : records) {
    TrackedFrame f = read_tracked_frame(file);
    if (f.tracked() && !fs::exists(f.mesh)) throw Error(f.mesh, "is missing (its record " + file.string() + " says tracked)");
    frames.push_back(std::move(f));
  }
  return frames;
}

}  // namespace tega::tracking
