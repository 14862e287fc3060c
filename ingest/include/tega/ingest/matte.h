#pragma once
// Mattes for captures without one (Multiface): the tracked mesh's silhouette,
// grown to take in the hair fringe the mesh lacks, with a soft edge
// (docs/multiface.md#matte).

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/silhouette.h"

namespace tega::ingest {

// One channel: 255 within `dilation_px` (Euclidean) of a non-zero pixel of
// `silhouette`, falling linearly to 0 over the next `feather_px`.
Image8 soft_dilate(const Image8& silhouette, double dilation_px, double feather_px);

}  // namespace tega::ingest
