// Multiface's per-frame vertex files: V x 3 little-endian float32, nothing else.

#include <cstring>
#include <string>

#include "mesh_io.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/mesh.h"

namespace tega {

namespace {
constexpr size_t kBytesPerVertex = 3 * sizeof(float);
}

Vertices read_vertices_bin(const std::filesystem::path& file, int expected_vertices) {
  const std::string bytes = read_text_file(file);
  if (bytes.size() % kBytesPerVertex != 0) {
    throw Error(file, "size " + std::to_string(bytes.size()) + " bytes is not a multiple of " +
                          std::to_string(kBytesPerVertex) + " (float32 x, y, z per vertex)");
  }
  const auto count = static_cast<Eigen::Index>(bytes.size() / kBytesPerVertex);
  if (expected_vertices > 0 && count != expected_vertices) {
    throw Error(file, "expected " + std::to_string(expected_vertices) + " vertices, found " + std::to_string(count));
  }
  Vertices vertices(count, 3);
  // An empty file is an empty mesh, whose data() is null: memcpy may not see it.
  if (count > 0) std::memcpy(vertices.data(), bytes.data(), bytes.size());
  return vertices;
}

void write_vertices_bin(const Vertices& vertices, const std::filesystem::path& file) {
  write_text_atomic(file, std::string_view(reinterpret_cast<const char*>(vertices.data()),
                                           static_cast<size_t>(vertices.size()) * sizeof(float)));
}

}  // namespace tega
