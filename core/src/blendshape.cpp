#include "tega/core/blendshape.h"

#include <algorithm>
#include <cctype>
#include <sstream>

#include "tega/core/error.h"
#include "tega/core/thread_pool.h"

namespace tega {

namespace fs = std::filesystem;

namespace {

constexpr const char* kNeutralFile = "generic_neutral_mesh.obj";

// A head, neck included, measures between these (metres) along its longest
// side; anything else means `metres_per_unit` does not match the files.
constexpr double kMinHeadSize = 0.05, kMaxHeadSize = 1.0;

bool is_identity_name(const std::string& stem) {
  constexpr std::string_view prefix = "identity";
  return stem.size() > prefix.size() && stem.starts_with(prefix) &&
         std::all_of(stem.begin() + prefix.size(), stem.end(), [](unsigned char c) { return std::isdigit(c); });
}

void add_deltas(Vertices& vertices, const std::vector<float>& coefficients, const std::vector<Vertices>& deltas,
                const char* kind) {
  if (coefficients.size() > deltas.size()) {
    throw Error("blendshape model: " + std::to_string(coefficients.size()) + " " + kind + " coefficients for " +
                std::to_string(deltas.size()) + " " + kind + " shapes");
  }
  for (size_t i = 0; i < coefficients.size(); ++i) {
    if (coefficients[i] != 0.0f) vertices += coefficients[i] * deltas[i];
  }
}

}  // namespace

int BlendshapeModel::expression_index(const std::string& name) const {
  const auto it = std::find(expression_names.begin(), expression_names.end(), name);
  return it == expression_names.end() ? -1 : static_cast<int>(it - expression_names.begin());
}

Vertices BlendshapeModel::evaluate(const std::vector<float>& identity, const std::vector<float>& expression) const {
  Vertices vertices = neutral.positions;
  add_deltas(vertices, identity, identity_deltas, "identity");
  add_deltas(vertices, expression, expression_deltas, "expression");
  return vertices;
}

Vertices BlendshapeModel::evaluate(const std::vector<float>& identity, const std::vector<float>& expression,
                                   const RigidTransform& head_to_world) const {
  Vertices vertices = evaluate(identity, expression);
  const Eigen::Matrix3f R = head_to_world.R.cast<float>();
  const Eigen::RowVector3f t = head_to_world.t.cast<float>().transpose();
  vertices = (vertices * R.transpose()).rowwise() + t;
  return vertices;
}

BlendshapeModel BlendshapeModel::load_directory(const fs::path& directory, double metres_per_unit) {
  if (!fs::is_directory(directory)) throw Error(directory, "is not a directory");
  if (!(metres_per_unit > 0)) throw Error(directory, "metres_per_unit must be positive");
  const fs::path neutral_file = directory / kNeutralFile;
  if (!fs::exists(neutral_file)) throw Error(neutral_file, "does not exist (the neutral mesh of the blendshape model)");

  BlendshapeModel model;
  std::vector<fs::path> identity_files, expression_files;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    const fs::path& file = entry.path();
    if (!entry.is_regular_file() || file.extension() != ".obj" || file.filename() == kNeutralFile) continue;
    (is_identity_name(file.stem().string()) ? identity_files : expression_files).push_back(file);
  }
  std::sort(identity_files.begin(), identity_files.end());
  std::sort(expression_files.begin(), expression_files.end());

  model.neutral = read_obj(neutral_file);
  const auto scale = static_cast<float>(metres_per_unit);
  model.neutral.positions *= scale;
  const Vertices& neutral = model.neutral.positions;
  const double size =
      neutral.rows() > 0 ? (neutral.colwise().maxCoeff() - neutral.colwise().minCoeff()).maxCoeff() : 0.0;
  if (size < kMinHeadSize || size > kMaxHeadSize) {
    std::ostringstream message;
    message << "spans " << size << " m with metres_per_unit " << metres_per_unit
            << ", not the size of a head: wrong units? (ICT-FaceKit is in centimetres: 0.01)";
    throw Error(neutral_file, message.str());
  }

  std::vector<fs::path> files = identity_files;
  files.insert(files.end(), expression_files.begin(), expression_files.end());
  std::vector<Vertices> deltas(files.size());
  // Each shape is a full mesh of a few MB of text: parsing dominates loading.
  ThreadPool pool(static_cast<int>(std::min<size_t>(files.size(), size_t(default_thread_count()))));
  pool.parallel_for(0, static_cast<int64_t>(files.size()), [&](int64_t i) {
    const fs::path& file = files[i];
    Mesh shape = read_obj(file);
    if (shape.num_vertices() != model.neutral.num_vertices()) {
      throw Error(file, "has " + std::to_string(shape.num_vertices()) + " vertices; the neutral mesh " +
                            kNeutralFile + " has " + std::to_string(model.neutral.num_vertices()));
    }
    if (shape.faces.rows() != model.neutral.faces.rows() || shape.faces != model.neutral.faces) throw Error(file, std::string("has other faces than ") + kNeutralFile);
    deltas[i] = shape.positions * scale - neutral;
  });

  for (size_t i = 0; i < files.size(); ++i) {
    const bool identity = i < identity_files.size();
    (identity ? model.identity_names : model.expression_names).push_back(files[i].stem().string());
    (identity ? model.identity_deltas : model.expression_deltas).push_back(std::move(deltas[i]));
  }
  return model;
}

}  // namespace tega
