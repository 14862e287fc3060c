// identity.json + identity_neutral.obj: a subject fitted once and reused for
// every take and session.
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/tracking/tracking.h"
#include "vertex_runs.h"

namespace tega::tracking {
namespace fs = std::filesystem;

void write_identity(const SubjectIdentity& subject, const HeadModel& model, const fs::path& file) {
  const fs::path mesh_file = file.parent_path() / (file.stem().string() + "_neutral.obj");
  Mesh neutral = model.shapes.neutral;
  neutral.positions = subject.neutral;
  write_obj(neutral, mesh_file);
  nlohmann::json j;
  j["model"] = fs::absolute(model.directory).string();
  j["model_vertices"] = model.num_vertices();
  nlohmann::json coefficients = nlohmann::json::object();
  for (size_t k = 0; k < subject.coefficients.size(); ++k)
    coefficients[model.shapes.identity_names[k]] = subject.coefficients[k];
  j["identity"] = coefficients;
  j["neutral"] = mesh_file.filename().string();
  if (!subject.open_eyes_covered.empty()) j["open_eyes_covered"] = subject.open_eyes_covered;
  // What later stages need of the model without loading it (tracked.h).
  j["eyeball_vertex_runs"] = vertex_runs(model.eyeball_vertices);
  j["landmark_vertices"] = model.landmark_vertices;
  write_text_atomic(file, j.dump(2) + "\n");
}

SubjectIdentity read_identity(const fs::path& file, const HeadModel& model) {
  SubjectIdentity subject;
  fs::path mesh_file;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    const int vertices = j.at("model_vertices");
    if (vertices != model.num_vertices())
      throw Error(file, "was fitted to a model with " + std::to_string(vertices) + " vertices, not " +
                            model.directory.string() + " (" + std::to_string(model.num_vertices()) + ")");
    const auto& coefficients = j.at("identity");
    for (const auto& name : model.shapes.identity_names)
      subject.coefficients.push_back(coefficients.contains(name) ? coefficients.at(name).get<double>() : 0.0);
    mesh_file = file.parent_path() / j.at("neutral").get<std::string>();
    if (j.contains("open_eyes_covered"))
      subject.open_eyes_covered = j.at("open_eyes_covered").get<std::map<std::string, double>>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid identity file: ") + e.what());
  }
  const Mesh neutral = read_obj(mesh_file);
  if (neutral.num_vertices() != model.num_vertices())
    throw Error(mesh_file, "has " + std::to_string(neutral.num_vertices()) + " vertices; the model has " +
                               std::to_string(model.num_vertices()));
  subject.neutral = neutral.positions;
  return subject;
}

}  // namespace tega::tracking
