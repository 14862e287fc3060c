#pragma once
// The one boundary between core's flat `tega::Mesh` and OpenMesh.
//
// tega keeps `Mesh` flat (row-major Eigen arrays of positions and triangle
// indices) because the trainer hands them to libtorch and CUDA as they are,
// every step, and because a halfedge structure cannot hold what the capture
// files hold: separately indexed UVs, polygons kept as numbered fans, and
// non-manifold pieces. Mesh processing that needs connectivity (decimation,
// smoothing, adjacency, components: tega/core/mesh_tools.h) converts here, once
// per call, and converts back (docs/architecture.md).

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <filesystem>

#include "tega/core/mesh.h"

namespace tega {

using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;

// What to do with a triangle a halfedge mesh cannot hold (a third triangle on
// an edge, a vertex joining two fans): `reject` throws tega::Error naming
// `source` and the triangle; `detach` adds it on copies of its vertices
// (appended after the mesh's own), as OpenMesh's own readers do, so it keeps
// its face handle but touches none of its neighbours. Reconstructed surfaces
// (Poisson, then trimmed) have such triangles.
enum class NonManifold { reject, detach };

// Vertex v becomes vertex handle v and triangle f face handle f. UVs and
// polygon numbers are not carried.
OpenMeshTriangles to_openmesh(const Mesh& mesh, const std::filesystem::path& source,
                              NonManifold non_manifold = NonManifold::reject);

// Positions and triangles of the live elements, in handle order; elements
// marked deleted (e.g. by decimation) are collected away first. No UVs.
Mesh from_openmesh(OpenMeshTriangles& mesh);

}  // namespace tega
