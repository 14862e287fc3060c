#pragma once
// Where a mesh covers a camera's image: the silhouette that mattes start from
// (ingest's Multiface mattes, matting/'s mesh prior).

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega {

// One channel: 255 where a pixel centre lies inside a triangle of the mesh
// (world space) projected through `camera`, its lens distortion included
// (vertices are distorted, edges stay straight: triangles are a few pixels
// wide), 0 elsewhere. Triangles reaching behind the camera are skipped.
Image8 mesh_silhouette(const Camera& camera, const Vertices& world, const Triangles& faces);

}  // namespace tega
