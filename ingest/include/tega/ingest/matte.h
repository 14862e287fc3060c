#pragma once
// Mattes for captures without one (Multiface): the tracked mesh's silhouette,
// grown to take in the hair fringe the mesh lacks, with a soft edge
// (docs/multiface.md#matte).

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega::ingest {

// One channel: 255 where a pixel centre lies inside a triangle of the mesh
// (world space) projected through the pinhole `camera` (its distortion is
// ignored), 0 elsewhere. Triangles reaching behind the camera are skipped.
Image8 mesh_silhouette(const Camera& camera, const Vertices& world, const Triangles& faces);

// One channel: 255 within `dilation_px` (Euclidean) of a non-zero pixel of
// `silhouette`, falling linearly to 0 over the next `feather_px`.
Image8 soft_dilate(const Image8& silhouette, double dilation_px, double feather_px);

// Averages each factor x factor block (each channel, rounded). Throws
// tega::Error unless factor divides both sides.
Image8 box_downsample(const Image8& image, int factor);

}  // namespace tega::ingest
