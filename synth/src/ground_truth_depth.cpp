#include "tega/synth/ground_truth_depth.h"

#include "tega/core/error.h"
#include "tega/synth/rasterizer.h"

namespace tega::synth {

ImageF render_depth(const Camera& camera, const Vertices& world_positions, const Triangles& faces) {
  if (camera.has_distortion()) throw Error("render_depth: the camera " + camera.name + " must be undistorted");
  Mesh mesh;
  mesh.positions = world_positions;
  mesh.faces = faces;
  const Vertices normals = mesh.vertex_normals();
  const Eigen::Matrix3f R = camera.world_to_camera.R.cast<float>();
  const Eigen::Vector3f t = camera.world_to_camera.t.cast<float>();
  Surface surface;
  surface.positions = &world_positions;
  surface.normals = &normals;
  surface.faces = &faces;
  surface.shade = [&](const SurfaceSample& s) {
    const float depth = (R * s.position + t).z();
    return Eigen::Vector3f(depth, depth, depth);
  };
  // One sample per pixel centre: a depth, not a blend of the surfaces a pixel straddles.
  const ImageF rgba = rasterize(camera, {surface}, 1);
  ImageF depth(camera.width, camera.height, 1);
  for (size_t i = 0; i < depth.pixels.size(); ++i)
    depth.pixels[i] = rgba.pixels[4 * i + 3] > 0.5f ? rgba.pixels[4 * i] / rgba.pixels[4 * i + 3] : 0.0f;
  return depth;
}

}  // namespace tega::synth
