#pragma once
// GaussianAvatars' rigging (Qian et al. 2024, §3.2), the baseline TeGA is
// measured against (docs/training.md#the-gaussianavatars-baseline). A point
// bound to a triangle lives in that triangle's frame:
//
//   T = the triangle's centroid
//   R = [t, n × t, n]    t: unit first edge (v1 − v0), n: unit face normal
//   k = (|v1 − v0| + h) / 2,  h: the triangle's height over that edge
//   x = T + k R μ,   J = ∂x/∂μ = k R
//
// so a Gaussian follows its triangle's rotation and size but, unlike TeGA's
// UVD map, not its shear or anisotropic stretch. Its covariance maps through
// J like any other: Σ_world = (k R R_q S)(k R R_q S)ᵀ, i.e. GA's rotation
// R R_q and scale k s.

#include <ATen/ATen.h>

#include "tega/uvd/uvd_map.h"

namespace tega::uvd {

struct TriangleFrames {
  at::Tensor origin;    // [F,3] centroids
  at::Tensor rotation;  // [F,3,3] columns: edge direction, in-plane perpendicular, normal
  at::Tensor scale;     // [F] k (0 for a degenerate triangle)
};

// The frames of every triangle faces [F,3] (int64) of vertices [V,3].
// Differentiable in the vertices.
TriangleFrames triangle_frames(const at::Tensor& vertices, const at::Tensor& faces);

// World positions and Jacobians of local coordinates μ [N,3] (in units of
// their triangle's k) bound to triangles [N] of the posed mesh. Gradients
// reach μ (and the mesh, where its vertices require grad). The returned
// mapping's `triangle` is `triangle`.
UvdMapping rigged_to_world(const at::Tensor& local, const at::Tensor& triangle, const PosedMesh& mesh,
                           const at::Tensor& faces);

}  // namespace tega::uvd
