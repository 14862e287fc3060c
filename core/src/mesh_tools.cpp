#include "tega/core/mesh_tools.h"

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Smoother/JacobiLaplaceSmootherT.hh>
#include <algorithm>
#include <string>

#include "tega/core/error.h"
#include "tega/core/openmesh.h"

namespace tega {

namespace {

// Component number of every face, and the number of faces in each.
struct FaceComponents {
  std::vector<int32_t> of_face;
  std::vector<int32_t> sizes;
};

FaceComponents face_components(const Mesh& mesh, const std::filesystem::path& source) {
  // A triangle that joins its neighbours non-manifoldly is its own component.
  const OpenMeshTriangles connectivity = to_openmesh(mesh, source, NonManifold::detach);
  FaceComponents components;
  components.of_face.assign(connectivity.n_faces(), -1);
  std::vector<OpenMeshTriangles::FaceHandle> pending;
  for (const auto seed : connectivity.faces()) {
    if (components.of_face[seed.idx()] >= 0) continue;
    const auto component = static_cast<int32_t>(components.sizes.size());
    components.sizes.push_back(0);
    components.of_face[seed.idx()] = component;
    pending.push_back(seed);
    while (!pending.empty()) {
      const auto face = pending.back();
      pending.pop_back();
      ++components.sizes[component];
      for (const auto neighbour : connectivity.ff_range(face)) {
        if (components.of_face[neighbour.idx()] < 0) {
          components.of_face[neighbour.idx()] = component;
          pending.push_back(neighbour);
        }
      }
    }
  }
  return components;
}

// Drops the rows of `elements` that `indices` does not use and renumbers
// `indices`; the rows that stay keep their order.
template <typename Elements>
void compact(Triangles& indices, Elements& elements) {
  std::vector<int32_t> new_index(elements.rows(), -1);
  for (Eigen::Index f = 0; f < indices.rows(); ++f) {
    for (int k = 0; k < 3; ++k) new_index[indices(f, k)] = 0;
  }
  int32_t used = 0;
  for (int32_t& index : new_index) {
    if (index == 0) index = used++;
  }
  Elements kept(used, elements.cols());
  for (Eigen::Index e = 0; e < elements.rows(); ++e) {
    if (new_index[e] >= 0) kept.row(new_index[e]) = elements.row(e);
  }
  for (Eigen::Index f = 0; f < indices.rows(); ++f) {
    for (int k = 0; k < 3; ++k) indices(f, k) = new_index[indices(f, k)];
  }
  elements = std::move(kept);
}

// The triangles of `mesh` whose component is kept, with what they use.
Mesh keep_faces(const Mesh& mesh, const FaceComponents& components, const std::vector<bool>& keep_component) {
  std::vector<Eigen::Index> faces;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    if (keep_component[components.of_face[f]]) faces.push_back(f);
  }
  const auto n = static_cast<Eigen::Index>(faces.size());
  Mesh result;
  result.positions = mesh.positions;
  result.faces.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) result.faces.row(i) = mesh.faces.row(faces[i]);
  compact(result.faces, result.positions);
  if (mesh.has_uvs()) {
    result.uvs = mesh.uvs;
    result.uv_faces.resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) result.uv_faces.row(i) = mesh.uv_faces.row(faces[i]);
    compact(result.uv_faces, result.uvs);
  }
  if (!mesh.triangle_polygon.empty()) {
    for (const Eigen::Index f : faces) result.triangle_polygon.push_back(mesh.triangle_polygon[f]);
  }
  return result;
}

}  // namespace

VertexAdjacency vertex_one_rings(const Mesh& mesh, const std::filesystem::path& source) {
  const OpenMeshTriangles connectivity = to_openmesh(mesh, source);
  VertexAdjacency adjacency;
  adjacency.offsets.reserve(connectivity.n_vertices() + 1);
  adjacency.neighbours.reserve(2 * connectivity.n_edges());
  adjacency.offsets.push_back(0);
  for (const auto vertex : connectivity.vertices()) {
    for (const auto neighbour : connectivity.vv_ccw_range(vertex)) adjacency.neighbours.push_back(neighbour.idx());
    adjacency.offsets.push_back(static_cast<int32_t>(adjacency.neighbours.size()));
  }
  return adjacency;
}

Vertices smooth_laplacian(const Mesh& mesh, int iterations, const std::filesystem::path& source) {
  OpenMeshTriangles smoothed = to_openmesh(mesh, source);
  OpenMesh::Smoother::JacobiLaplaceSmootherT<OpenMeshTriangles> smoother(smoothed);
  smoother.initialize(decltype(smoother)::Tangential_and_Normal, decltype(smoother)::C0);
  smoother.smooth(static_cast<unsigned int>(std::max(iterations, 0)));
  return from_openmesh(smoothed).positions;
}

Mesh decimate(const Mesh& mesh, int target_faces, const std::filesystem::path& source) {
  OpenMeshTriangles decimated = to_openmesh(mesh, source);
  OpenMesh::Decimater::DecimaterT<OpenMeshTriangles> decimater(decimated);
  OpenMesh::Decimater::ModQuadricT<OpenMeshTriangles>::Handle quadric;
  decimater.add(quadric);
  decimater.module(quadric).unset_max_err();
  if (!decimater.initialize()) throw Error(source, "OpenMesh's decimater could not be initialised");
  decimater.decimate_to_faces(0, static_cast<size_t>(std::max(target_faces, 0)));
  return from_openmesh(decimated);
}

Mesh remove_small_components(const Mesh& mesh, int min_faces, const std::filesystem::path& source) {
  const FaceComponents components = face_components(mesh, source);
  std::vector<bool> keep(components.sizes.size());
  for (size_t c = 0; c < keep.size(); ++c) keep[c] = components.sizes[c] >= min_faces;
  return keep_faces(mesh, components, keep);
}

Mesh keep_largest_component(const Mesh& mesh, const std::filesystem::path& source) {
  const FaceComponents components = face_components(mesh, source);
  std::vector<bool> keep(components.sizes.size(), false);
  if (!keep.empty()) {
    keep[std::max_element(components.sizes.begin(), components.sizes.end()) - components.sizes.begin()] = true;
  }
  return keep_faces(mesh, components, keep);
}

}  // namespace tega
