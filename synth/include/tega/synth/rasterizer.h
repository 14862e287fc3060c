#pragma once
// A small CPU rasterizer through a distorted camera. Vertices are projected
// with the camera's lens distortion and triangles are filled in the captured
// (distorted) image; the meshes it draws are fine enough (a few pixels a
// triangle) that straight edges between distorted vertices stay well below a
// tenth of a pixel from the true curved ones. Antialiasing by supersampling
// (S x S samples a pixel, a box filter); the image is filled tile by tile so
// memory stays small at any resolution. Back faces (clockwise as the camera
// sees them, for meshes wound counter-clockwise seen from outside) are culled.

#include <functional>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega::synth {

struct SurfaceSample {
  int triangle = 0;
  Eigen::Vector3f barycentric;  // perspective-correct
  Eigen::Vector3f position;     // world
  Eigen::Vector3f normal;       // world, unit length
  Eigen::Vector2f uv;           // (0, 0) for meshes without UVs
  Eigen::Vector3f to_camera;    // unit vector from the point to the camera
};

struct Surface {
  const Vertices* positions = nullptr;  // world space
  const Vertices* normals = nullptr;    // world space, per vertex
  const Triangles* faces = nullptr;
  const UVs* uvs = nullptr;             // may be null
  const Triangles* uv_faces = nullptr;  // may be null
  std::function<Eigen::Vector3f(const SurfaceSample&)> shade;
};

// RGBA, premultiplied: rgb = sum of the shaded samples / S^2, a = coverage.
// `camera`'s distortion is honoured; pass a camera without distortion for a
// pinhole image.
ImageF rasterize(const Camera& camera, const std::vector<Surface>& surfaces, int supersampling);

}  // namespace tega::synth
