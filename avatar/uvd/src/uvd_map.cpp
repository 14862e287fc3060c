#include "tega/uvd/uvd_map.h"

#include "fused_uvd_map.h"
#include "fused_uvd_map_math.h"
#include "tega/uvd/covariance.h"

namespace tega::uvd {
namespace {

using fused_uvd_map::kMinNormalLength;

// rows [N*3] of table [*,C] -> [N,3,C]
at::Tensor corners_of(const at::Tensor& table, const at::Tensor& corner_index) {
  return table.index_select(0, corner_index.reshape(-1)).view({corner_index.size(0), 3, table.size(1)});
}

// F and J_F at valid_uv [N,2] in triangle [N] as differentiable tensor ops:
// the path for posed meshes that take gradients themselves.
std::pair<at::Tensor, at::Tensor> composed_uvd_to_world(const at::Tensor& uvd, const at::Tensor& valid_uv,
                                                        const at::Tensor& triangle, const PosedMesh& mesh,
                                                        const UvTriangleLookup& lookup) {
  const auto d = uvd.slice(1, 2, 3);  // [N,1]
  const auto b = lookup.barycentrics_in(valid_uv, triangle).unsqueeze(-1);  // [N,3,1]
  const auto db = lookup.barycentric_gradient(uvd.scalar_type()).index_select(0, triangle);  // [N,3,2]
  const auto corner_index = lookup.faces().index_select(0, triangle);
  const auto v = corners_of(mesh.vertices, corner_index);  // [N,corner,xyz]
  const auto nv = corners_of(mesh.normals, corner_index);

  const auto position = (b * v).sum(1);  // [N,3]
  const auto m = (b * nv).sum(1);
  const auto m_length = m.norm(2, 1, /*keepdim=*/true).clamp_min(kMinNormalLength);
  const auto n = m / m_length;

  const auto dposition = batched_matmul(v.transpose(1, 2), db);  // [N,3,2]
  const auto dm = batched_matmul(nv.transpose(1, 2), db);
  const auto dn = (dm - n.unsqueeze(-1) * (n.unsqueeze(-1) * dm).sum(1, /*keepdim=*/true)) / m_length.unsqueeze(-1);
  const auto jacobian = at::cat({dposition + d.unsqueeze(-1) * dn, n.unsqueeze(-1)}, 2);
  return {position + d * n, jacobian};
}

}  // namespace

at::Tensor vertex_normals(const at::Tensor& vertices, const at::Tensor& faces) {
  const auto corners = corners_of(vertices, faces);
  // The unnormalised cross product has length 2·area: area weighting for free.
  const auto face_normal =
      at::cross(corners.select(1, 1) - corners.select(1, 0), corners.select(1, 2) - corners.select(1, 0), 1);
  const auto sum = at::zeros_like(vertices).index_add(0, faces.reshape(-1), face_normal.repeat_interleave(3, 0));
  return sum / sum.norm(2, 1, /*keepdim=*/true).clamp_min(1e-30);
}

PosedMesh pose(const UvTriangleLookup& lookup, const at::Tensor& vertices) {
  TORCH_CHECK(vertices.dim() == 2 && vertices.size(1) == 3, "pose: vertices must be [V,3]");
  TORCH_CHECK(vertices.device() == lookup.device(), "pose: vertices and lookup on different devices");
  return {vertices, vertex_normals(vertices, lookup.faces())};
}

UvdMapping uvd_to_world(const at::Tensor& uvd, const PosedMesh& mesh, const UvTriangleLookup& lookup,
                        const at::Tensor& bound_triangle) {
  TORCH_CHECK(uvd.dim() == 2 && uvd.size(1) == 3, "uvd_to_world: uvd must be [N,3]");
  TORCH_CHECK(uvd.scalar_type() == mesh.vertices.scalar_type() && uvd.scalar_type() == mesh.normals.scalar_type(),
              "uvd_to_world: uvd and the posed mesh must share a dtype");
  TORCH_CHECK(uvd.device() == lookup.device() && mesh.vertices.device() == lookup.device() &&
                  mesh.normals.device() == lookup.device(),
              "uvd_to_world: uvd, the posed mesh and the lookup must share a device");
  TORCH_CHECK(mesh.vertices.dim() == 2 && mesh.vertices.size(1) == 3 && mesh.normals.sizes() == mesh.vertices.sizes(),
              "uvd_to_world: the posed mesh's vertices and normals must both be [V,3]");
  TORCH_CHECK(mesh.vertices.size(0) == lookup.num_vertices(), "uvd_to_world: the posed mesh has ",
              mesh.vertices.size(0), " vertices, the template ", lookup.num_vertices());
  const auto uv = uvd.slice(1, 0, 2);

  at::Tensor triangle, mapped_uv;  // mapped_uv: where F is evaluated
  if (bound_triangle.defined()) {
    TORCH_CHECK(bound_triangle.dim() == 1 && bound_triangle.size(0) == uvd.size(0),
                "uvd_to_world: bound_triangle must be [N]");
    triangle = bound_triangle.to(at::kLong);
    // The fused evaluation reads the tables at these indices unchecked. On the
    // GPU the check is queued, not read back: reading it waited for all queued
    // work every training step (checkpoints' indices are checked on loading).
    const at::Tensor in_range = ((triangle >= 0) & (triangle < lookup.num_triangles())).all();
    if (triangle.is_cuda())
      at::_assert_async(in_range);
    else
      TORCH_CHECK(in_range.item<bool>(), "uvd_to_world: bound_triangle out of range");
    mapped_uv = uv.detach();
  } else {
    const UvHit hit = lookup.lookup(uv);
    triangle = hit.triangle;
    mapped_uv = hit.uv;
  }

  if (mesh.vertices.requires_grad() || mesh.normals.requires_grad()) {
    // Value of the mapped uv, gradient of the query (straight through).
    const auto valid_uv = bound_triangle.defined() ? uv : uv + (mapped_uv - uv).detach();
    auto [xyz, jacobian] = composed_uvd_to_world(uvd, valid_uv, triangle, mesh, lookup);
    return {xyz, jacobian, triangle};
  }
  auto [xyz, jacobian] = fused_uvd_to_world(uvd, mapped_uv, triangle, mesh, lookup);
  return {xyz, jacobian, triangle};
}

}  // namespace tega::uvd
