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

// Vertex v becomes vertex handle v and triangle f face handle f. UVs and
// polygon numbers are not carried. Throws tega::Error naming `source` when a
// triangle cannot be added: a non-manifold edge or vertex, which a halfedge
// mesh cannot represent.
OpenMeshTriangles to_openmesh(const Mesh& mesh, const std::filesystem::path& source);

// Positions and triangles of the live elements, in handle order; elements
// marked deleted (e.g. by decimation) are collected away first. No UVs.
Mesh from_openmesh(OpenMeshTriangles& mesh);

}  // namespace tega
