#pragma once
// Linear blendshape head models: a neutral mesh plus identity and expression
// shapes in one topology. vertices = neutral + sum_i a_i (identity_i - neutral)
//                                            + sum_j b_j (expression_j - neutral),
// then a rigid head pose (head space -> world).

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega {

struct BlendshapeModel {
  Mesh neutral;                                // template topology with UVs, in metres
  std::vector<std::string> identity_names;     // e.g. identity000
  std::vector<Vertices> identity_deltas;       // shape - neutral, V x 3 each
  std::vector<std::string> expression_names;   // e.g. jawOpen, eyeBlink_L
  std::vector<Vertices> expression_deltas;

  int num_vertices() const { return neutral.num_vertices(); }
  int expression_index(const std::string& name) const;  // -1 when absent

  // Coefficient vectors may be shorter than the number of shapes (missing
  // ones are 0); longer ones throw tega::Error.
  Vertices evaluate(const std::vector<float>& identity, const std::vector<float>& expression) const;
  Vertices evaluate(const std::vector<float>& identity, const std::vector<float>& expression,
                    const RigidTransform& head_to_world) const;

  // Loads a directory laid out like ICT-FaceKit: generic_neutral_mesh.obj,
  // identityNNN.obj and every other *.obj as an expression named after its
  // file. `metres_per_unit` converts the files' units (ICT-FaceKit: 0.01, cm).
  // Throws tega::Error naming the file when a shape's topology differs.
  static BlendshapeModel load_directory(const std::filesystem::path& directory,
                                        double metres_per_unit);
};

}  // namespace tega
