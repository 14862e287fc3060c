#pragma once
// Where a mesh covers a camera's image: the silhouette that mattes start from
// (ingest's Multiface mattes, matting/'s mesh prior).

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega {

// Which triangles cover the image.
enum class Facing {
  any,            // all: the region a subject fills around an open mesh (a neck's cut) too
  toward_camera,  // those whose outward side (counter-clockwise winding) faces the camera: the
                  // surface a renderer shows, with the background seen through an open cut
};

// One channel: 255 where a pixel centre lies inside a triangle of the mesh
// (world space) projected through `camera`, its lens distortion included
// (vertices are distorted, edges stay straight: triangles are a few pixels
// wide), 0 elsewhere. Triangles reaching behind the camera are skipped.
Image8 mesh_silhouette(const Camera& camera, const Vertices& world, const Triangles& faces,
                       Facing facing = Facing::any);

}  // namespace tega
