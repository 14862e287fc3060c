#pragma once
// Triangle meshes with UVs. Positions and UVs are indexed separately (as in
// OBJ and Multiface meshes), so a vertex on a UV seam has one position and
// several UVs. Polygons are triangulated on load; `triangle_polygon` keeps
// the index of the source polygon of every triangle, so part ranges given in
// polygon indices (e.g. ICT-FaceKit's eyeballs) stay usable.
//
// Writers put the triangles of one source polygon back together, so a mesh
// read and written keeps its polygons and their indices.
//
// Formats (docs/meshes-and-images.md):
//  - OBJ (v, vt, f with v, v/vt, v/vt/vn or v//vn, negative indices too;
//    normals are ignored)
//  - PLY, ASCII or binary little-endian, with UVs as the per-face
//    "texcoord" list property (MeshLab's convention, which keeps seams).
//    Reading rebuilds the UV array in order of first use, without duplicates.
//  - .bin: raw little-endian float32 vertex positions, V x 3 (Multiface)

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "tega/core/geometry.h"

namespace tega {

using Vertices = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using UVs = Eigen::Matrix<float, Eigen::Dynamic, 2, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Every vertex moved by `transform`, each in double precision.
Vertices transformed(const RigidTransform& transform, const Vertices& vertices);

struct Mesh {
  Vertices positions;                    // V x 3
  Triangles faces;                       // F x 3, indices into positions
  UVs uvs;                               // T x 2 (empty: no UVs); v = 0 at the bottom, as in OBJ
  Triangles uv_faces;                    // F x 3 indices into uvs (empty when uvs is)
  std::vector<int32_t> triangle_polygon; // F entries: source polygon of each triangle
                                         // (empty: every triangle is its own polygon)

  int num_vertices() const { return static_cast<int>(positions.rows()); }
  int num_faces() const { return static_cast<int>(faces.rows()); }
  bool has_uvs() const { return uvs.rows() > 0; }

  // Throws tega::Error (naming `source`) on an index out of range or a
  // face/uv_face/triangle_polygon count mismatch.
  void validate(const std::filesystem::path& source) const;
  // Area-weighted per-vertex normals (unit length; zero for isolated vertices).
  Vertices vertex_normals() const;
};

// Readers validate what they read and throw tega::Error naming the file (and,
// for OBJ, the line) on malformed input.
Mesh read_obj(const std::filesystem::path& file);
void write_obj(const Mesh& mesh, const std::filesystem::path& file);  // atomic
Mesh read_ply(const std::filesystem::path& file);
void write_ply(const Mesh& mesh, const std::filesystem::path& file);  // binary LE, atomic
// By extension: .obj or .ply (any other throws tega::Error).
Mesh read_mesh(const std::filesystem::path& file);
void write_mesh(const Mesh& mesh, const std::filesystem::path& file);

// Raw float32 positions. `expected_vertices` > 0 checks the count and throws
// tega::Error naming the file when it differs.
Vertices read_vertices_bin(const std::filesystem::path& file, int expected_vertices = 0);
void write_vertices_bin(const Vertices& vertices, const std::filesystem::path& file);  // atomic

}  // namespace tega
