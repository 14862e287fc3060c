#include "tega/uvd/triangle_rig.h"

namespace tega::uvd {
namespace {

// Below this (metres), a length is a degenerate triangle's; its frame is then
// arbitrary but finite, and its k is 0.
constexpr double kMinLength = 1e-12;

at::Tensor normalised(const at::Tensor& v) { return v / v.norm(2, 1, /*keepdim=*/true).clamp_min(kMinLength); }

}  // namespace

TriangleFrames triangle_frames(const at::Tensor& vertices, const at::Tensor& faces) {
  TORCH_CHECK(vertices.dim() == 2 && vertices.size(1) == 3, "triangle_frames: vertices must be [V,3]");
  TORCH_CHECK(faces.dim() == 2 && faces.size(1) == 3, "triangle_frames: faces must be [F,3]");
  const at::Tensor v0 = vertices.index_select(0, faces.select(1, 0));
  const at::Tensor v1 = vertices.index_select(0, faces.select(1, 1));
  const at::Tensor v2 = vertices.index_select(0, faces.select(1, 2));
  const at::Tensor edge = v1 - v0;
  const at::Tensor tangent = normalised(edge);
  const at::Tensor normal = normalised(at::cross(edge, v2 - v0, 1));
  const at::Tensor bitangent = at::cross(normal, tangent, 1);
  TriangleFrames frames;
  frames.origin = (v0 + v1 + v2) / 3.0;
  frames.rotation = at::stack({tangent, bitangent, normal}, 2);
  const at::Tensor base = edge.norm(2, 1);
  const at::Tensor height = ((v2 - v0) * bitangent).sum(1).abs();
  frames.scale = 0.5 * (base + height);
  return frames;
}

UvdMapping rigged_to_world(const at::Tensor& local, const at::Tensor& triangle, const PosedMesh& mesh,
                           const at::Tensor& faces) {
  TORCH_CHECK(local.dim() == 2 && local.size(1) == 3, "rigged_to_world: local coordinates must be [N,3]");
  TORCH_CHECK(triangle.dim() == 1 && triangle.size(0) == local.size(0), "rigged_to_world: triangle must be [N]");
  TORCH_CHECK(local.scalar_type() == mesh.vertices.scalar_type(),
              "rigged_to_world: the local coordinates and the posed mesh must share a dtype");
  // index_select checks the range itself; an explicit check would wait for
  // the GPU on every training step.
  const at::Tensor index = triangle.to(at::kLong);
  const TriangleFrames frames = triangle_frames(mesh.vertices, faces);
  const at::Tensor jacobian =
      frames.rotation.index_select(0, index) * frames.scale.index_select(0, index).view({-1, 1, 1});
  UvdMapping mapping;
  mapping.xyz = frames.origin.index_select(0, index) + (jacobian * local.unsqueeze(1)).sum(2);
  mapping.jacobian = jacobian;
  mapping.triangle = index;
  return mapping;
}

}  // namespace tega::uvd
