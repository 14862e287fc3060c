#include "tega/core/tracked.h"

#include <algorithm>
#include <cstdio>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega {
namespace fs = std::filesystem;

namespace {

// Vertex index sets stored compactly, as sorted [first, last] runs.
nlohmann::json vertex_runs(std::vector<int> vertices) {
  std::sort(vertices.begin(), vertices.end());
  nlohmann::json runs = nlohmann::json::array();
  for (size_t i = 0; i < vertices.size();) {
    size_t j = i;
    while (j + 1 < vertices.size() && vertices[j + 1] <= vertices[j] + 1) ++j;
    runs.push_back({vertices[i], vertices[j]});
    i = j + 1;
  }
  return runs;
}

}  // namespace

TrackedSubject read_tracked_subject_file(const fs::path& file) {
  TrackedSubject subject;
  fs::path mesh_file;
  int model_vertices = 0;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    subject.model = j.at("model").get<std::string>();
    model_vertices = j.at("model_vertices");
    mesh_file = file.parent_path() / j.at("neutral").get<std::string>();
    if (!j.contains("eyeball_vertex_runs"))
      throw Error(file, "was written by an older tega track (no eyeball_vertex_runs): track the subject again");
    for (const auto& run : j.at("eyeball_vertex_runs"))
      for (int v = run.at(0).get<int>(); v <= run.at(1).get<int>(); ++v) subject.eyeball_vertices.push_back(v);
    subject.landmark_vertices = j.at("landmark_vertices").get<std::vector<int>>();
    subject.identity = j.at("identity").get<std::map<std::string, double>>();
    if (j.contains("open_eyes_covered"))
      subject.open_eyes_covered = j.at("open_eyes_covered").get<std::map<std::string, double>>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid identity file: ") + e.what());
  }
  subject.neutral = read_obj(mesh_file);
  const int count = subject.neutral.num_vertices();
  if (count != model_vertices)
    throw Error(mesh_file, "has " + std::to_string(count) + " vertices; " + file.string() + " says its model has " +
                               std::to_string(model_vertices));
  const auto out_of_range = [count](int v) { return v < 0 || v >= count; };
  if (std::any_of(subject.eyeball_vertices.begin(), subject.eyeball_vertices.end(), out_of_range) ||
      std::any_of(subject.landmark_vertices.begin(), subject.landmark_vertices.end(), out_of_range))
    throw Error(file, "names vertices beyond the " + std::to_string(count) + " of " + mesh_file.string());
  return subject;
}

TrackedSubject read_tracked_subject(const fs::path& tracked) {
  const fs::path file = tracked / "identity.json";
  if (!fs::exists(file)) throw Error(file, "is missing: " + tracked.string() + " is not the output of tega track");
  return read_tracked_subject_file(file);
}

void write_tracked_subject(const TrackedSubject& subject, const fs::path& file) {
  const fs::path mesh_file = file.parent_path() / (file.stem().string() + "_neutral.obj");
  write_obj(subject.neutral, mesh_file);
  nlohmann::json j;
  j["model"] = subject.model.string();
  j["model_vertices"] = subject.neutral.num_vertices();
  j["identity"] = subject.identity;
  j["neutral"] = mesh_file.filename().string();
  if (!subject.open_eyes_covered.empty()) j["open_eyes_covered"] = subject.open_eyes_covered;
  j["eyeball_vertex_runs"] = vertex_runs(subject.eyeball_vertices);
  j["landmark_vertices"] = subject.landmark_vertices;
  write_text_atomic(file, j.dump(2) + "\n");
}

TrackedFrame read_tracked_frame(const fs::path& file) {
  TrackedFrame f;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    f.frame = j.at("frame");
    f.status = j.at("status");
    f.reason = j.value("reason", "");
    f.fitted_afresh = j.value("fitted_afresh", false);
    if (f.status != "skipped") {
      Eigen::Matrix<double, 3, 4> m;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = j.at("head_to_world").at(r).at(c);
      f.head_to_world = RigidTransform::from_matrix(m);
      for (const auto& [name, value] : j.at("expression").items()) f.expression[name] = value.get<double>();
      f.residuals = j.at("residuals");
    }
    if (f.tracked()) f.mesh = file.parent_path() / j.at("mesh").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid frame record: ") + e.what());
  }
  return f;
}

fs::path tracked_frame_file(const fs::path& take_dir, int frame, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d%s", frame, extension);
  return take_dir / name;
}

void write_tracked_frame(const fs::path& take_dir, const TrackedFrame& frame, const Vertices* mesh) {
  nlohmann::json j;
  j["frame"] = frame.frame;
  j["status"] = frame.status;
  if (!frame.reason.empty()) j["reason"] = frame.reason;
  if (frame.fitted_afresh) j["fitted_afresh"] = true;
  if (frame.status != "skipped") {
    const auto m = frame.head_to_world.matrix();
    j["head_to_world"] = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) j["head_to_world"].push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
    j["expression"] = frame.expression;
    j["residuals"] = frame.residuals;
  }
  if (mesh) {
    const fs::path bin = tracked_frame_file(take_dir, frame.frame, ".bin");
    write_vertices_bin(*mesh, bin);
    j["mesh"] = bin.filename().string();
  }
  write_text_atomic(tracked_frame_file(take_dir, frame.frame, ".json"), j.dump(2) + "\n");
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

}  // namespace tega
