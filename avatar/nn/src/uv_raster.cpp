#include "tega/nn/uv_raster.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tega/core/error.h"

namespace tega::nn {
namespace {

// Texel centres on a shared edge belong to both triangles; the tolerance keeps
// them from falling through the crack in floating point.
constexpr double kEdgeTolerance = 1e-9;

std::vector<int32_t> every_face(const Mesh& mesh) {
  std::vector<int32_t> faces(mesh.num_faces());
  std::iota(faces.begin(), faces.end(), 0);
  return faces;
}

}  // namespace

UvRasterizer::UvRasterizer(const Mesh& mesh, int size) : UvRasterizer(mesh, size, every_face(mesh)) {}

UvRasterizer::UvRasterizer(const Mesh& mesh, int size, const std::vector<int32_t>& faces)
    : size_(size), num_vertices_(mesh.num_vertices()) {
  if (!mesh.has_uvs()) throw Error("UV rasterizer: the template mesh has no UVs");
  if (size <= 0) throw Error("UV rasterizer: texture size must be positive, not " + std::to_string(size));
  if (mesh.uv_faces.rows() != mesh.faces.rows())
    throw Error("UV rasterizer: the template has " + std::to_string(mesh.faces.rows()) + " faces but " +
                std::to_string(mesh.uv_faces.rows()) + " UV faces");

  const int64_t texels = int64_t{size} * size;
  triangle_ = at::full({size, size}, -1, at::kLong);
  vertices_ = at::zeros({texels, 3}, at::kLong);
  weights_ = at::zeros({texels, 3}, at::kFloat);
  auto triangle = triangle_.accessor<int64_t, 2>();
  auto vertices = vertices_.accessor<int64_t, 2>();
  auto weights = weights_.accessor<float, 2>();

  for (const int32_t f : faces) {
    if (f < 0 || f >= mesh.num_faces())
      throw Error("UV rasterizer: face " + std::to_string(f) + " is not one of the template's " +
                  std::to_string(mesh.num_faces()) + " faces");
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      const int t = mesh.uv_faces(f, k);
      const int p = mesh.faces(f, k);
      if (t < 0 || t >= mesh.uvs.rows() || p < 0 || p >= mesh.num_vertices())
        throw Error("UV rasterizer: face " + std::to_string(f) + " has an index out of range");
      u[k] = mesh.uvs(t, 0);
      v[k] = mesh.uvs(t, 1);
    }
    const double area = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);
    if (area == 0) continue;  // degenerate in UV: covers no texel centre
    // Texel columns/rows whose centres may lie inside the triangle's box.
    const auto col = [&](double uu) { return uu * size - 0.5; };
    const auto row = [&](double vv) { return (1 - vv) * size - 0.5; };
    const int c0 = std::max(0, static_cast<int>(std::ceil(col(std::min({u[0], u[1], u[2]})))));
    const int c1 = std::min(size - 1, static_cast<int>(std::floor(col(std::max({u[0], u[1], u[2]})))));
    const int r0 = std::max(0, static_cast<int>(std::ceil(row(std::max({v[0], v[1], v[2]})))));
    const int r1 = std::min(size - 1, static_cast<int>(std::floor(row(std::min({v[0], v[1], v[2]})))));
    for (int r = r0; r <= r1; ++r) {
      const double pv = 1 - (r + 0.5) / size;
      for (int c = c0; c <= c1; ++c) {
        const double pu = (c + 0.5) / size;
        const double b1 = ((pu - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (pv - v[0])) / area;
        const double b2 = ((u[1] - u[0]) * (pv - v[0]) - (pu - u[0]) * (v[1] - v[0])) / area;
        const double b0 = 1 - b1 - b2;
        if (b0 < -kEdgeTolerance || b1 < -kEdgeTolerance || b2 < -kEdgeTolerance) continue;
        const int64_t texel = int64_t{r} * size + c;
        triangle[r][c] = f;
        const double b[3] = {b0, b1, b2};
        for (int k = 0; k < 3; ++k) {
          vertices[texel][k] = mesh.faces(f, k);
          weights[texel][k] = static_cast<float>(b[k]);
        }
      }
    }
  }
}

at::Tensor UvRasterizer::rasterize(const at::Tensor& values) const {
  TORCH_CHECK(values.dim() == 2 && values.size(0) == num_vertices_, "values must be [", num_vertices_,
              ",C], got ", values.sizes());
  TORCH_CHECK(values.device() == vertices_.device(), "UvRasterizer tables are on ", vertices_.device(),
              ", values on ", values.device(), ": call to()");
  const int64_t channels = values.size(1);
  const at::Tensor corners = values.index_select(0, vertices_.view(-1)).view({-1, 3, channels});
  const at::Tensor texels = (corners * weights_.to(values.scalar_type()).unsqueeze(2)).sum(1);  // [N*N,C]
  return texels.t().reshape({channels, size_, size_});
}

UvRasterizer UvRasterizer::to(const at::Device& device) const {
  UvRasterizer moved;
  moved.size_ = size_;
  moved.num_vertices_ = num_vertices_;
  moved.triangle_ = triangle_.to(device);
  moved.vertices_ = vertices_.to(device);
  moved.weights_ = weights_.to(device);
  return moved;
}

}  // namespace tega::nn
