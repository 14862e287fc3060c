#pragma once
// Points spread uniformly by area over a mesh's triangles, deterministically.

#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::scoring {

// About one point per spacing² of area: each triangle gets its area's share,
// the fraction decided by a draw, at uniformly random barycentric positions.
// `faces`: the triangles to sample (empty: all). The same seed gives the same points.
Vertices sample_surface(const Mesh& mesh, const std::vector<int>& faces, double spacing_m, uint64_t seed);

}  // namespace tega::scoring
