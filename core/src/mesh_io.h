#pragma once
// What the mesh readers and writers share (private to tega_core).

#include <bit>
#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::detail {

// PLY and .bin bodies are copied to and from memory as they are.
static_assert(std::endian::native == std::endian::little,
              "mesh I/O assumes a little-endian host (x86-64, AArch64)");

// Consecutive triangles that the writers emit as one polygon.
struct PolygonRun {
  int32_t first_triangle;
  int32_t num_triangles;  // corners = num_triangles + 2
};

// Regroups the fans that the readers made from each source polygon (same
// `triangle_polygon`, shared first corner, each triangle continuing the
// previous one, in positions and UVs alike) so that written files keep the
// polygons of the files read. Anything else, and any polygon of more than
// `max_corners` corners, is emitted one triangle at a time.
std::vector<PolygonRun> polygon_runs(const Mesh& mesh, int max_corners);

}  // namespace tega::detail
