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

// The UV islands of `faces`: the groups of triangles that share UV entries,
// each in ascending face order, the groups in order of their first face.
std::vector<std::vector<int32_t>> uv_islands(const Mesh& mesh, const std::vector<int32_t>& faces);

// `mesh` with the triangles of `part` moved off the rest's UVs when any of
// them overlaps the rest's; otherwise `mesh` unchanged. Each UV island of the
// part is moved on its own, since a part's islands may lie on top of each
// other too (ICT-FaceKit's four eyeball charts all fill the face's tile).
// The islands are scaled to the rest's UV density (UV area per world area),
// so that sampling by UV area spreads Gaussians evenly over both, and packed
// in rows into the unit tiles right of the rest's UV bounding box, a
// sixteenth of a tile apart, so that a Gaussian drifting off one chart is not
// snapped onto another (smaller when an island would not fit a tile). Only
// the part's UVs change: positions, faces and the rest's UVs stay as they
// are (UV entries the part shares with the rest are copied). Throws
// tega::Error when the mesh has no UVs or a face is out of range.
Mesh with_part_laid_apart(const Mesh& mesh, const std::vector<int32_t>& part);

// `mesh` with its UV layout fitted into the unit square, where the
// expression networks read it (TeGA §3.4-3.6: uv in [0, 1]); unchanged when
// it lies there already. Multi-tile (UDIM) layouts, such as ICT-FaceKit's
// face, head, gums and teeth tiles, have their occupied unit tiles (an island
// belongs to the tile of its bounding box's centre) arranged in a k x k grid
// of cells, k = ceil(sqrt(tiles)), in order of v then u, each tile scaled by
// the same factor with a gap of a thirty-second of a cell between cells. The
// layout's shape within each tile is kept, so relative UV densities are too.
// Throws tega::Error when the mesh has no UVs.
Mesh packed_in_unit_square(const Mesh& mesh);

}  // namespace tega::uvd
