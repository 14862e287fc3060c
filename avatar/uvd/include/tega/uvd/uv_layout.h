#pragma once
// The UV layout Gaussians live in (docs/uvd-rigging.md#parts-that-share-the-faces-uv-tile).
//
// UVD space needs every uv to name one surface point. Some templates lay a
// part over the face's UV tile: ICT-FaceKit's eyeball charts lie on top of
// the face and make up 46 % of its layout's UV area. There the uv -> triangle
// lookup answers with one of the two surfaces, so Gaussians sampled on the
// part end up on the face and the part gets almost none.

#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::uvd {

// The summed UV and world areas of the given triangles.
struct SurfaceAreas {
  double uv = 0, world = 0;
};
SurfaceAreas surface_areas(const Mesh& mesh, const std::vector<int32_t>& faces);

// `mesh` with the triangles of `part` given a UV island of their own when
// any of them overlaps the rest's UVs; otherwise `mesh` unchanged. The moved
// island is scaled to the rest's UV density (UV area per world area), so
// that sampling by UV area spreads Gaussians evenly over both, and placed
// to the right of the rest's UV bounding box with a gap of a sixteenth of
// its size, so that a Gaussian drifting off one chart is not snapped onto
// the other. Only the part's UVs change: positions, faces and the rest's
// UVs stay as they are (UV entries the part shares with the rest are
// copied). Throws tega::Error when the mesh has no UVs or a face is out of
// range.
Mesh with_part_laid_apart(const Mesh& mesh, const std::vector<int32_t>& part);

}  // namespace tega::uvd
