#include "tega/uvd/uv_lookup.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cmath>

#include "lookup_builder.h"

namespace tega::uvd {

UvTriangleLookup::UvTriangleLookup(const Mesh& mesh, const UvLookupOptions& options,
                                   const std::vector<int32_t>& active_faces) {
  LookupBuilder::build(*this, mesh, options, active_faces);
}

const UvTriangleLookup::Tables& UvTriangleLookup::tables(at::ScalarType dtype) const {
  TORCH_CHECK(dtype == at::kFloat || dtype == at::kDouble, "uv lookup: uv must be float32 or float64");
  return dtype == at::kFloat ? float_ : double_;
}

const at::Tensor& UvTriangleLookup::barycentric_gradient(at::ScalarType dtype) const {
  return tables(dtype).gradient;
}

const at::Tensor& UvTriangleLookup::uv_corners(at::ScalarType dtype) const { return tables(dtype).corners; }

const at::Tensor& UvTriangleLookup::barycentric_inverse(at::ScalarType dtype) const { return tables(dtype).inverse; }

at::Tensor UvTriangleLookup::barycentrics_in(const at::Tensor& uv, const at::Tensor& triangle) const {
  const Tables& t = tables(uv.scalar_type());
  const auto corner0 = t.corners.index_select(0, triangle).select(1, 0);
  // Relative to a corner, so float32 keeps its precision on small triangles.
  const auto b12 = (t.inverse.index_select(0, triangle) * (uv - corner0).unsqueeze(1)).sum(2);  // [N,2,2]·[N,2]
  return at::cat({1 - b12.sum(1, /*keepdim=*/true), b12}, 1);
}

std::tuple<at::Tensor, at::Tensor, at::Tensor> UvTriangleLookup::closest_points(const at::Tensor& uv,
                                                                               const at::Tensor& triangle) const {
  const Tables& t = tables(uv.scalar_type());
  const auto corners = t.corners.index_select(0, triangle);  // [P,3,2]
  const auto b = barycentrics_in(uv, triangle);
  const auto inside = std::get<0>(b.min(1)) >= 0;
  // Closest points on the three edges; edge k runs from corner k to corner k+1.
  const auto edge = corners.roll(-1, 1) - corners;
  const auto offset = uv.unsqueeze(1) - corners;
  const auto s = ((offset * edge).sum(-1) / (edge * edge).sum(-1)).clamp(0, 1);  // [P,3]
  const auto on_edge = corners + s.unsqueeze(-1) * edge;
  const auto [edge_distance2, k] = (uv.unsqueeze(1) - on_edge).pow(2).sum(-1).min(1);
  const auto point = on_edge.gather(1, k.view({-1, 1, 1}).expand({-1, 1, 2})).squeeze(1);
  const auto eye = at::eye(3, uv.options());
  const auto edge_b = (1 - s).unsqueeze(-1) * eye + s.unsqueeze(-1) * eye.roll(1, 1);  // [P,edge,corner]
  const auto point_b = edge_b.gather(1, k.view({-1, 1, 1}).expand({-1, 1, 3})).squeeze(1);
  return {at::where(inside, at::zeros_like(edge_distance2), edge_distance2),
          at::where(inside.unsqueeze(1), uv, point), at::where(inside.unsqueeze(1), b, point_b)};
}

UvTriangleLookup::Nearest UvTriangleLookup::nearest_candidate(const at::Tensor& uv, const at::Tensor& start,
                                                               const at::Tensor& count) const {
  // One row per (query, candidate); keep the first closest candidate of each query.
  const int64_t n = uv.size(0);
  const auto long_options = start.options();
  const auto owner = at::repeat_interleave(at::arange(n, long_options), count);
  const int64_t pairs = owner.size(0);
  const auto pair_index = at::arange(pairs, long_options);
  const auto rank = pair_index - (count.cumsum(0) - count).index_select(0, owner);
  const auto candidate = cell_triangles_.index_select(0, start.index_select(0, owner) + rank).to(at::kLong);
  const auto [d2, q, b] = closest_points(uv.index_select(0, owner), candidate);
  const auto best = at::full({n}, INFINITY, d2.options()).scatter_reduce(0, owner, d2, "amin");
  const auto key = at::where(d2 <= best.index_select(0, owner), pair_index, at::full_like(pair_index, pairs));
  const auto chosen = at::full({n}, pairs, long_options).scatter_reduce(0, owner, key, "amin");
  return {candidate.index_select(0, chosen), d2.index_select(0, chosen), q.index_select(0, chosen),
          b.index_select(0, chosen)};
}

UvHit UvTriangleLookup::lookup(const at::Tensor& uv_in) const {
  TORCH_CHECK(uv_in.dim() == 2 && uv_in.size(1) == 2, "uv lookup: uv must be [N,2]");
  TORCH_CHECK(uv_in.device() == device(), "uv lookup: uv is on ", uv_in.device(), ", the lookup on ", device());
  const auto uv = uv_in.detach();
  const int64_t n = uv.size(0);
  if (n == 0) return {at::empty({0}, uv.options().dtype(at::kLong)), uv.new_empty({0, 3}), uv.clone(), uv.new_empty({0})};
  auto texel = [&](int axis) {
    return ((uv.select(1, axis) - origin_[axis]) / texel_[axis]).floor().clamp(0, cells_[axis] - 1).to(at::kLong);
  };
  const auto cell = texel(1) * cells_[0] + texel(0);
  const auto start = cell_offsets_.index_select(0, cell).to(at::kLong);
  const auto count = cell_offsets_.index_select(0, cell + 1).to(at::kLong) - start;

  // A texel's first candidate contains its centre (where one does), so most
  // valid queries are settled by it; the rest try all their candidates.
  Nearest found;
  found.triangle = cell_triangles_.index_select(0, start).to(at::kLong);
  std::tie(found.distance2, found.point, found.barycentrics) = closest_points(uv, found.triangle);
  const auto unsettled = ((found.distance2 > 0) & (count > 1)).nonzero().view({-1});
  if (unsettled.size(0) > 0) {
    const Nearest rest =
        nearest_candidate(uv.index_select(0, unsettled), start.index_select(0, unsettled), count.index_select(0, unsettled));
    found.triangle.index_copy_(0, unsettled, rest.triangle);
    found.distance2.index_copy_(0, unsettled, rest.distance2);
    found.point.index_copy_(0, unsettled, rest.point);
    found.barycentrics.index_copy_(0, unsettled, rest.barycentrics);
  }
  return {found.triangle, found.barycentrics, found.point, found.distance2.sqrt()};
}

at::Tensor UvTriangleLookup::project_to_valid_uv(const at::Tensor& uv) const { return lookup(uv).uv; }

at::Tensor UvTriangleLookup::sample_uniform(int64_t n, uint64_t seed) const {
  auto generator = at::detail::createCPUGenerator(seed);
  const auto triangle = at::multinomial(uv_area_.cpu(), n, /*replacement=*/true, generator);
  const auto r = at::rand({n, 2}, generator, at::kDouble);
  // sqrt warps the first coordinate so that the density is uniform over the triangle.
  const auto s = r.select(1, 0).sqrt();
  const auto t = r.select(1, 1);
  const auto b = at::stack({1 - s, s * (1 - t), s * t}, 1);
  const auto corners = double_.corners.cpu().index_select(0, triangle);
  return (b.unsqueeze(-1) * corners).sum(1).to(at::kFloat).to(device());
}

UvTriangleLookup::Tables UvTriangleLookup::tables_to(const Tables& t, const at::Device& device) {
  return {t.corners.to(device), t.inverse.to(device), t.gradient.to(device)};
}

UvTriangleLookup UvTriangleLookup::to(const at::Device& device) const {
  UvTriangleLookup copy = *this;
  copy.cell_offsets_ = cell_offsets_.to(device);
  copy.cell_triangles_ = cell_triangles_.to(device);
  copy.faces_ = faces_.to(device);
  copy.uv_area_ = uv_area_.to(device);
  copy.float_ = tables_to(float_, device);
  copy.double_ = tables_to(double_, device);
  return copy;
}

}  // namespace tega::uvd
