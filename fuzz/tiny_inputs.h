#pragma once
// Small valid inputs shared by the seed writer and the targets that need
// valid files beside the fuzzed one (a dataset's rig and template).

#include "tega/core/mesh.h"
#include "tega/core/rig.h"

namespace tega::fuzz {

// Cameras cam00 .. cam<count-1>, 64 x 48, looking at the origin from 1 m, with
// mild distortion when `distorted`.
Rig tiny_rig(int count, bool distorted);
// Two triangles of one quad (polygon 0) and one triangle (polygon 1), with a
// UV seam: positions and UVs indexed differently.
Mesh tiny_mesh();

}  // namespace tega::fuzz
