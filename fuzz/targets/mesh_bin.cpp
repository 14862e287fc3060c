#include "fuzz_target.h"
#include "tega/core/mesh.h"

// tega's (and Multiface's) raw float32 vertex positions, with and without an
// expected vertex count.
TEGA_FUZZ_TARGET(mesh_bin) {
  const auto file = tega::fuzz::input_file("mesh.bin", data, size);
  const auto vertices = tega::read_vertices_bin(file);
  tega::read_vertices_bin(file, static_cast<int>(vertices.rows()) + 1);
}
