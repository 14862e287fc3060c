#pragma once
// Per-vertex values (displacements) → a UV texture, for the expression
// encoder's input (TeGA §3.4: tracked minus neutral vertex positions, pose
// zeroed, rasterised in UV space).
//
// The template's UV triangles are rasterised once: every texel centre gets the
// triangle that covers it and its barycentrics there. Each frame is then a
// gather and a weighted sum, on whatever device the values live.
//
// Texel (row r, column c) of an N x N texture has its centre at
// u = (c + 0.5)/N, v = 1 - (r + 0.5)/N: row 0 is the top, v = 0 (OBJ) the
// bottom; sample_latent() (encoders.h) reads with the same convention.
// Texels whose centre no UV triangle covers hold 0, which is also "no
// displacement", so the encoder sees no spurious signal in the gaps. Where
// drawn UV triangles overlap (mirrored charts), the later triangle wins, so
// parts that share the face's UV tile must be left out: ICT-FaceKit's eyeball
// spheres cover all of tile 0 and come after the face, and drawn they hid
// nearly every face texel (the encoder saw no expression).
//
// Interpolation is linear, so rasterize(x) - rasterize(neutral) equals
// rasterize(x - neutral).

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::nn {

class UvRasterizer {
 public:
  // Draws every triangle, or only `faces`. Throws tega::Error if the mesh has
  // no UVs, size is not positive or a face index is out of range.
  UvRasterizer(const Mesh& mesh, int size);
  UvRasterizer(const Mesh& mesh, int size, const std::vector<int32_t>& faces);

  // values [V,C] (V = mesh.num_vertices()) → [C,N,N], differentiable in values.
  // The tables must be on values' device (see to()).
  at::Tensor rasterize(const at::Tensor& values) const;

  UvRasterizer to(const at::Device& device) const;

  int size() const { return size_; }
  // [N,N] int64: the covering triangle of each texel, -1 for none.
  const at::Tensor& triangle_ids() const { return triangle_; }

 private:
  UvRasterizer() = default;

  int size_ = 0;
  int64_t num_vertices_ = 0;
  at::Tensor triangle_;  // [N,N] int64
  at::Tensor vertices_;  // [N*N,3] int64 position indices (0 where uncovered)
  at::Tensor weights_;   // [N*N,3] float barycentrics (0 where uncovered)
};

}  // namespace tega::nn
