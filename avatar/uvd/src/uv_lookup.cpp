#include "tega/uvd/uv_lookup.h"

#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>

#include <cmath>

#include "lookup_builder.h"
#include "tega/avatar/device_dispatch.h"
#include "uv_lookup_glue.h"

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

template <typename T>
uv_lookup::Grid<T> UvTriangleLookup::grid() const {
  const Tables& t = tables(c10::CppTypeToScalarType<T>::value);
  uv_lookup::Grid<T> g;
  g.cell_offsets = cell_offsets_.data_ptr<int32_t>();
  g.cell_triangles = cell_triangles_.data_ptr<int32_t>();
  g.corners = t.corners.data_ptr<T>();
  g.inverse = t.inverse.data_ptr<T>();
  for (int axis = 0; axis < 2; ++axis) {
    g.cells[axis] = cells_[axis];
    g.origin[axis] = T(origin_[axis]);
    g.texel[axis] = T(texel_[axis]);
  }
  return g;
}

UvHit UvTriangleLookup::lookup(const at::Tensor& uv_in) const {
  TORCH_CHECK(uv_in.dim() == 2 && uv_in.size(1) == 2, "uv lookup: uv must be [N,2]");
  TORCH_CHECK(uv_in.device() == device(), "uv lookup: uv is on ", uv_in.device(), ", the lookup on ", device());
  const at::Tensor uv = uv_in.detach().contiguous();
  const int64_t n = uv.size(0);
  UvHit hit{at::empty({n}, uv.options().dtype(at::kLong)), at::empty({n, 3}, uv.options()),
            at::empty({n, 2}, uv.options()), at::empty({n}, uv.options())};
  AT_DISPATCH_FLOATING_TYPES(uv.scalar_type(), "uv lookup", [&] {
    const uv_lookup::Grid<scalar_t> g = grid<scalar_t>();
    const uv_lookup::Answers<scalar_t> out{hit.triangle.data_ptr<int64_t>(), hit.barycentrics.data_ptr<scalar_t>(),
                                           hit.uv.data_ptr<scalar_t>(), hit.distance.data_ptr<scalar_t>()};
    if (use_cuda_kernels(uv, "uv lookup")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      uv_lookup::lookup_cuda(g, uv, out);
#endif
    } else {
      const scalar_t* queries = uv.data_ptr<scalar_t>();
      at::parallel_for(0, n, 4096, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) uv_lookup::lookup_point(g, queries, i, out);
      });
    }
  });
  return hit;
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
