#pragma once
// Mesh processing for the studio stages (MVS meshing, template tracking),
// done by OpenMesh through the boundary in tega/core/openmesh.h. Inputs must
// be manifold triangle meshes (tega::Error naming `source` otherwise).
// Area-weighted vertex normals stay `Mesh::vertex_normals`: a flat loop that
// also takes non-manifold meshes, and equals OpenMesh's on manifold ones.

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "tega/core/mesh.h"

namespace tega {

// The one-ring of every vertex: the vertices sharing an edge with it,
// counter-clockwise around it (as OpenMesh circulates).
struct VertexAdjacency {
  std::vector<int32_t> offsets;     // V + 1 entries
  std::vector<int32_t> neighbours;  // those of vertex v: [offsets[v], offsets[v + 1])

  std::span<const int32_t> of(int32_t vertex) const {
    return {neighbours.data() + offsets[vertex], neighbours.data() + offsets[vertex + 1]};
  }
};
VertexAdjacency vertex_one_rings(const Mesh& mesh, const std::filesystem::path& source = "mesh");

// Jacobi Laplacian smoothing with uniform weights (OpenMesh's
// JacobiLaplaceSmootherT, tangential and normal, C0); boundary vertices stay
// where they are. Returns the new positions; topology and UVs are unchanged.
Vertices smooth_laplacian(const Mesh& mesh, int iterations, const std::filesystem::path& source = "mesh");

// Collapses edges by least quadric error (OpenMesh's Decimater with
// ModQuadricT) until at most `target_faces` triangles remain, or no collapse
// is legal. The result has no UVs and no polygon numbers.
Mesh decimate(const Mesh& mesh, int target_faces, const std::filesystem::path& source = "mesh");

// Drops connected components (faces joined by edges) of fewer than
// `min_faces` triangles, and the vertices only they used. A triangle that
// joins its neighbours non-manifoldly (a third one on an edge) counts as a
// component of its own. What stays keeps its
// order, UVs and polygon numbers; vertices are renumbered compactly.
Mesh remove_small_components(const Mesh& mesh, int min_faces, const std::filesystem::path& source = "mesh");
// Keeps only the component with the most triangles (the first such one on a tie).
Mesh keep_largest_component(const Mesh& mesh, const std::filesystem::path& source = "mesh");

}  // namespace tega
