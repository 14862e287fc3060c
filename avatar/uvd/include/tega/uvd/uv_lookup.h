#pragma once
// uv -> triangle lookup on a template's UV layout (docs/uvd-rigging.md).
//
// Built once per template on the CPU: a texel grid over the UV bounding box of
// the active triangles (grown by a margin) where every texel lists the
// candidate triangles that can contain, or be nearest to, any point of the
// texel. A query is one texel
// fetch plus an exact point-in-triangle / closest-point test against the
// texel's candidates, so the answer is exact (not limited by the resolution):
//  - a uv inside a triangle returns that triangle and its barycentrics
//    (on a shared edge, either triangle);
//  - a uv outside every triangle (in a hole, across a seam, beyond the chart)
//    returns the closest point of the nearest triangle.
// Queries run on the device of the lookup's tensors (move it with to()): a
// loop on the CPU, a kernel on the GPU that never waits for the device.
// Exactness holds inside the grid's domain; a uv beyond it is answered from
// the nearest border texel's candidates, so it lands on a triangle, not
// necessarily the nearest (such a uv means nothing anyway).
// Only active triangles are returned; zero-area UV triangles never are.
// UV islands must not overlap among the active triangles (ICT-FaceKit's eyes,
// eye blend and occlusion meshes share the face's UV tile, so activate the
// face and head triangles only, or lay those parts out apart): where islands
// overlap, a uv names two surface points and either may be returned.

#include <ATen/ATen.h>

#include <cstdint>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::uvd::uv_lookup {
template <typename T>
struct Grid;
}

namespace tega::uvd {

struct UvLookupOptions {
  double resolution = 1024;
  double margin = 0.1;
  template <class V>
  void visit(V& v) {
    v("resolution", resolution,
      "Texels per unit of uv in the uv -> triangle grid. Any value gives exact lookups; higher "
      "ones mean fewer candidate triangles per query and more memory and build time "
      "(docs/uvd-rigging.md#performance).");
    v("margin", margin,
      "Grid domain: the UV bounding box grown by this much uv on every side. Lookups are exact "
      "inside it.");
  }
};

struct UvHit {
  at::Tensor triangle;      // [N] int64: the containing (or nearest) triangle
  at::Tensor barycentrics;  // [N,3] of `uv` in `triangle`, each in [0,1]
  at::Tensor uv;            // [N,2] the query itself, or its closest valid point
  at::Tensor distance;      // [N] |query - uv| (0 for a valid query)
};

class UvTriangleLookup {
 public:
  // active_faces: the triangles that carry Gaussians (empty: all). Throws
  // tega::Error when the mesh has no UVs, an index is out of range, or no
  // active UV triangle has nonzero area.
  explicit UvTriangleLookup(const Mesh& mesh, const UvLookupOptions& options = {},
                            const std::vector<int32_t>& active_faces = {});

  // uv: [N,2] float or double on the lookup's device. Not differentiable.
  UvHit lookup(const at::Tensor& uv) const;
  // The closest valid uv of every query: lookup(uv).uv.
  at::Tensor project_to_valid_uv(const at::Tensor& uv) const;
  // Barycentrics of uv [N,2] in given triangles [N], extrapolated affinely
  // (negative outside the triangle), as GaussianAvatars-style binding needs.
  at::Tensor barycentrics_in(const at::Tensor& uv, const at::Tensor& triangle) const;
  // n points distributed uniformly over the valid UV area (by UV area), float32
  // on the lookup's device; deterministic for a seed.
  at::Tensor sample_uniform(int64_t n, uint64_t seed) const;

  // A copy whose tensors live on `device`.
  UvTriangleLookup to(const at::Device& device) const;
  at::Device device() const { return faces_.device(); }

  int64_t num_texels() const { return int64_t(cells_[0]) * cells_[1]; }
  int64_t num_triangles() const { return faces_.size(0); }
  int64_t num_vertices() const { return num_vertices_; }  // of the mesh it was built from
  int64_t num_candidates() const { return cell_triangles_.size(0); }  // summed over texels
  const at::Tensor& faces() const { return faces_; }      // [F,3] int64 position indices
  const at::Tensor& uv_area() const { return uv_area_; }  // [F] float64, 0 unless active and nondegenerate
  // ∂(b0,b1,b2)/∂(u,v) of every triangle: [F,3,2] of the given floating dtype
  // (zero for degenerate triangles).
  const at::Tensor& barycentric_gradient(at::ScalarType dtype) const;
  // The tables behind barycentrics_in, for fused ops that evaluate it per
  // point: uv of the corners [F,3,2], and [F,2,2] mapping (u,v) - corner 0 to
  // (b1,b2), of the given floating dtype.
  const at::Tensor& uv_corners(at::ScalarType dtype) const;
  const at::Tensor& barycentric_inverse(at::ScalarType dtype) const;

 private:
  struct Tables {
    at::Tensor corners;   // [F,3,2] uv of the corners
    at::Tensor inverse;   // [F,2,2] (u,v) - corner0 -> (b1,b2)
    at::Tensor gradient;  // [F,3,2] ∂b/∂(u,v)
  };
  const Tables& tables(at::ScalarType dtype) const;
  static Tables tables_to(const Tables& t, const at::Device& device);
  // The grid and tables as raw pointers for the per-query loop and kernel.
  template <typename T>
  uv_lookup::Grid<T> grid() const;

  int cells_[2] = {0, 0};      // texels along u and v
  double origin_[2] = {0, 0};  // uv of the grid's lower-left corner
  double texel_[2] = {1, 1};   // texel size in u and v
  at::Tensor cell_offsets_;    // [cells+1] int32 into cell_triangles_; texel (i,j) is cell j*cells_[0]+i
  at::Tensor cell_triangles_;  // int32 candidate triangles, grouped by cell
  at::Tensor faces_;           // [F,3] int64
  at::Tensor uv_area_;         // [F] float64
  int64_t num_vertices_ = 0;
  Tables float_, double_;

  friend struct LookupBuilder;
};

}  // namespace tega::uvd
