#include "tega/core/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <string>

#include "mesh_io.h"
#include "tega/core/error.h"

namespace tega {

Vertices transformed(const RigidTransform& transform, const Vertices& vertices) {
  Vertices out(vertices.rows(), 3);
  for (Eigen::Index v = 0; v < vertices.rows(); ++v)
    out.row(v) = transform.apply(vertices.row(v).transpose().cast<double>()).cast<float>().transpose();
  return out;
}

namespace {

// Names the first index of `indices` outside [0, count).
void check_indices(const Triangles& indices, int count, const char* what, const char* target,
                   const std::filesystem::path& source) {
  for (Eigen::Index f = 0; f < indices.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int32_t i = indices(f, k);
      if (i < 0 || i >= count) {
        throw Error(source, std::string(what) + " " + std::to_string(f) + " refers to " + target + " " +
                                std::to_string(i) + ", out of range [0, " + std::to_string(count) + ")");
      }
    }
  }
}

std::string lowercase_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

void Mesh::validate(const std::filesystem::path& source) const {
  check_indices(faces, num_vertices(), "face", "vertex", source);
  if (has_uvs()) {
    if (uv_faces.rows() != faces.rows()) {
      throw Error(source, std::to_string(faces.rows()) + " faces but " + std::to_string(uv_faces.rows()) +
                              " UV faces");
    }
    check_indices(uv_faces, static_cast<int>(uvs.rows()), "UV face", "UV", source);
  } else if (uv_faces.rows() != 0) {
    throw Error(source, "has UV faces but no UVs");
  }
  if (!triangle_polygon.empty() && triangle_polygon.size() != static_cast<size_t>(faces.rows())) {
    throw Error(source, std::to_string(faces.rows()) + " faces but " + std::to_string(triangle_polygon.size()) +
                            " source polygon indices");
  }
}

Vertices Mesh::vertex_normals() const {
  Vertices normals = Vertices::Zero(positions.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3f a = positions.row(faces(f, 0));
    const Eigen::Vector3f b = positions.row(faces(f, 1));
    const Eigen::Vector3f c = positions.row(faces(f, 2));
    // The cross product's length is twice the area: summing it weights by area.
    const Eigen::RowVector3f n = (b - a).cross(c - a).transpose();
    for (int k = 0; k < 3; ++k) normals.row(faces(f, k)) += n;
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const float length = normals.row(v).norm();
    if (length > 0) normals.row(v) /= length;
  }
  return normals;
}

Mesh read_mesh(const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  if (ext == ".obj") return read_obj(file);
  if (ext == ".ply") return read_ply(file);
  throw Error(file, "unknown mesh format (expected .obj or .ply)");
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& file) {
  const std::string ext = lowercase_extension(file);
  if (ext == ".obj") return write_obj(mesh, file);
  if (ext == ".ply") return write_ply(mesh, file);
  throw Error(file, "unknown mesh format (expected .obj or .ply)");
}

namespace detail {

std::vector<PolygonRun> polygon_runs(const Mesh& mesh, int max_corners) {
  const int32_t num_faces = mesh.num_faces();
  const bool uvs = mesh.has_uvs();
  // Whether triangle t continues the fan that starts at triangle `first`.
  const auto continues_fan = [&](int32_t first, int32_t t) {
    const auto same_fan = [&](const Triangles& tris) {
      return tris(t, 0) == tris(first, 0) && tris(t, 1) == tris(t - 1, 2);
    };
    return mesh.triangle_polygon[t] == mesh.triangle_polygon[first] && same_fan(mesh.faces) &&
           (!uvs || same_fan(mesh.uv_faces));
  };

  std::vector<PolygonRun> runs;
  runs.reserve(num_faces);
  for (int32_t first = 0; first < num_faces;) {
    int32_t end = first + 1;
    if (!mesh.triangle_polygon.empty()) {
      // A polygon's triangles all share its index; a run only counts when
      // every one of them continues the fan.
      while (end < num_faces && mesh.triangle_polygon[end] == mesh.triangle_polygon[first]) ++end;
      bool fan = end - first + 2 <= max_corners;
      for (int32_t t = first + 1; fan && t < end; ++t) fan = continues_fan(first, t);
      if (!fan) {
        for (int32_t t = first; t < end; ++t) runs.push_back({t, 1});
        first = end;
        continue;
      }
    }
    runs.push_back({first, end - first});
    first = end;
  }
  return runs;
}

}  // namespace detail
}  // namespace tega
