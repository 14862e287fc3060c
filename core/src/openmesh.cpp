#include "tega/core/openmesh.h"

#include <OpenMesh/Core/System/omstream.hh>
#include <string>

#include "tega/core/error.h"

namespace tega {

static_assert(sizeof(OpenMeshTriangles::Point) == 3 * sizeof(float),
              "OpenMesh points are copied to and from Vertices as flat float arrays");

OpenMeshTriangles to_openmesh(const Mesh& mesh, const std::filesystem::path& source, NonManifold non_manifold) {
  mesh.validate(source);
  // Refused triangles are reported here (naming the file) or detached on purpose:
  // OpenMesh's own complaints on stderr would only repeat or contradict that.
  const bool was_enabled = omerr().is_enabled();
  omerr().disable();
  struct Restore {
    bool enable;
    ~Restore() {
      if (enable) omerr().enable();
    }
  } restore{was_enabled};
  OpenMeshTriangles result;
  result.reserve(mesh.positions.rows(), 3 * mesh.faces.rows(), mesh.faces.rows());
  for (Eigen::Index v = 0; v < mesh.positions.rows(); ++v) {
    result.add_vertex({mesh.positions(v, 0), mesh.positions(v, 1), mesh.positions(v, 2)});
  }
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const OpenMeshTriangles::FaceHandle face =
        result.add_face(result.vertex_handle(mesh.faces(f, 0)), result.vertex_handle(mesh.faces(f, 1)),
                        result.vertex_handle(mesh.faces(f, 2)));
    if (!face.is_valid() && non_manifold == NonManifold::detach) {
      // add_face has complained on OpenMesh's error stream; the copies settle it.
      OpenMeshTriangles::VertexHandle copies[3];
      for (int k = 0; k < 3; ++k) copies[k] = result.add_vertex(result.point(result.vertex_handle(mesh.faces(f, k))));
      if (result.add_face(copies[0], copies[1], copies[2]).is_valid()) continue;
    }
    if (!face.is_valid()) {
      throw Error(source, "triangle " + std::to_string(f) + " (" + std::to_string(mesh.faces(f, 0)) + " " +
                              std::to_string(mesh.faces(f, 1)) + " " + std::to_string(mesh.faces(f, 2)) +
                              ") is degenerate or makes the mesh non-manifold; OpenMesh cannot hold it");
    }
  }
  return result;
}

Mesh from_openmesh(OpenMeshTriangles& mesh) {
  if (mesh.has_vertex_status() && mesh.has_edge_status() && mesh.has_face_status()) mesh.garbage_collection();
  Mesh result;
  result.positions = Eigen::Map<const Vertices>(reinterpret_cast<const float*>(mesh.points()),
                                                static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  result.faces.resize(static_cast<Eigen::Index>(mesh.n_faces()), 3);
  for (const auto face : mesh.faces()) {
    int k = 0;
    for (const auto vertex : mesh.fv_range(face)) result.faces(face.idx(), k++) = vertex.idx();
  }
  return result;
}

}  // namespace tega
