#pragma once
// Ground truth for depth estimation: what a pinhole camera sees of a mesh, as
// depth along the camera's z axis per pixel (0 where the mesh does not cover
// the pixel centre). Rendered by the studio's own rasterizer, so it matches
// what the camera images show.

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega::synth {

// `camera` must be undistorted; `world_positions` are the mesh's vertices in
// world space (e.g. a frame's fine mesh), `faces` its triangles.
ImageF render_depth(const Camera& camera, const Vertices& world_positions, const Triangles& faces);

}  // namespace tega::synth
