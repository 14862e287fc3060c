#pragma once
// uvd_to_world's evaluation once every point's triangle is known, as one
// fused op (fused_uvd_map_math.h has the math): barycentrics, interpolated
// position and normal, F and J_F. Its backward reaches uvd only, so
// uvd_to_world uses it where the posed mesh takes no gradient.

#include <ATen/core/Tensor.h>

#include <utility>

#include "tega/uvd/uv_lookup.h"
#include "tega/uvd/uvd_map.h"

namespace tega::uvd {

// uvd [N,3]; mapped_uv [N,2] the uv each point is evaluated at (its own, or
// its projection onto the valid layout: the gradient passes straight through
// to uvd's u and v); triangle [N] int64. Returns (xyz [N,3], J_F [N,3,3]).
std::pair<at::Tensor, at::Tensor> fused_uvd_to_world(const at::Tensor& uvd, const at::Tensor& mapped_uv,
                                                     const at::Tensor& triangle, const PosedMesh& mesh,
                                                     const UvTriangleLookup& lookup);

}  // namespace tega::uvd
