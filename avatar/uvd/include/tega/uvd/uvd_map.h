#pragma once
// F(uvd): canonical uvd coordinates -> world points on the posed mesh, and its
// Jacobian J_F (TeGA §3.3, docs/uvd-rigging.md):
//
//   b = barycentrics of (u,v) in its triangle (affine in u,v)
//   P = Σ bᵢ vᵢ,  m = Σ bᵢ nᵢ,  n = m/|m|,  F = P + d n
//   J_F = [∂P/∂u + d ∂n/∂u,  ∂P/∂v + d ∂n/∂v,  n],  ∂n = (I − n nᵀ) ∂m / |m|
//
// vᵢ are the posed positions of the triangle's corners and nᵢ the posed
// mesh's area-weighted vertex normals. Everything runs on the inputs' device,
// and the gradient w.r.t. uvd is exact: ∂xyz/∂uvd = J_F, and J_F itself is
// differentiated through the normal's normalisation and d, which the
// covariance J Σ Jᵀ needs. Once the triangles are known, F and J_F are one
// fused op (CPU loops or CUDA kernels) whose gradient reaches uvd only; a
// posed mesh whose vertices or normals require grad is mapped with
// differentiable tensor ops instead, so that gradients reach it too. A uv
// outside every triangle is moved to its closest valid point; its gradient
// passes straight through that projection (docs).

#include <ATen/ATen.h>

#include "tega/uvd/uv_lookup.h"

namespace tega::uvd {

// Area-weighted unit vertex normals of vertices [V,3] with faces [F,3] int64
// (zero for a vertex in no face of nonzero area). Differentiable.
at::Tensor vertex_normals(const at::Tensor& vertices, const at::Tensor& faces);

struct PosedMesh {
  at::Tensor vertices;  // [V,3]
  at::Tensor normals;   // [V,3] unit
};
// The template's topology with posed vertices [V,3] (one frame), normals computed once.
PosedMesh pose(const UvTriangleLookup& lookup, const at::Tensor& vertices);

struct UvdMapping {
  at::Tensor xyz;       // [N,3]
  at::Tensor jacobian;  // [N,3,3] J_F: columns ∂xyz/∂u, ∂xyz/∂v, ∂xyz/∂d
  at::Tensor triangle;  // [N] int64, the triangle each point was mapped through
};

// uvd [N,3] of the mesh's dtype (float32 or float64), on the lookup's device.
// `bound_triangle` [N] switches to GaussianAvatars-style binding: every point
// uses its given triangle, whose barycentric map is extrapolated affinely
// beyond its edges (no lookup, no projection), so the point stays attached to
// that triangle wherever its uv moves.
UvdMapping uvd_to_world(const at::Tensor& uvd, const PosedMesh& mesh, const UvTriangleLookup& lookup,
                        const at::Tensor& bound_triangle = at::Tensor());

}  // namespace tega::uvd
