#include "tega/nn/uv_raster.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/nn/encoders.h"

namespace tega::nn {
namespace {

// A square UV chart [0.2,0.7] x [0.3,0.9] made of two triangles. Position and
// UV indices differ (UV indices run in reverse), as across an OBJ seam.
Mesh square_chart() {
  Mesh mesh;
  mesh.positions.resize(4, 3);
  mesh.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 0, 2, 3;
  mesh.uvs.resize(4, 2);  // uvs[3 - i] belongs to position i
  mesh.uvs << 0.2f, 0.9f, 0.7f, 0.9f, 0.7f, 0.3f, 0.2f, 0.3f;
  mesh.uv_faces.resize(2, 3);
  mesh.uv_faces << 3, 2, 1, 3, 1, 0;
  return mesh;
}

constexpr int kSize = 20;

// UV of texel centres, as documented in uv_raster.h.
double texel_u(int c) { return (c + 0.5) / kSize; }
double texel_v(int r) { return 1 - (r + 0.5) / kSize; }
bool inside_chart(int r, int c) {
  return texel_u(c) >= 0.2 && texel_u(c) <= 0.7 && texel_v(r) >= 0.3 && texel_v(r) <= 0.9;
}

TEST(UvRasterizer, ConstantDisplacementFillsTheChartAndLeavesZeroOutside) {
  const UvRasterizer raster(square_chart(), kSize);
  const at::Tensor texture = raster.rasterize(at::tensor({0.01f, -0.02f, 0.03f}).repeat({4, 1}));
  ASSERT_EQ(texture.sizes(), (std::vector<int64_t>{3, kSize, kSize}));
  const auto t = texture.accessor<float, 3>();
  const auto ids = raster.triangle_ids().accessor<int64_t, 2>();
  int covered = 0;
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c) {
      SCOPED_TRACE(testing::Message() << "texel " << r << "," << c);
      if (inside_chart(r, c)) {
        ++covered;
        EXPECT_GE(ids[r][c], 0);
        EXPECT_NEAR(t[0][r][c], 0.01f, 1e-7);
        EXPECT_NEAR(t[1][r][c], -0.02f, 1e-7);
        EXPECT_NEAR(t[2][r][c], 0.03f, 1e-7);
      } else {
        EXPECT_EQ(ids[r][c], -1);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(t[k][r][c], 0.0f);
      }
    }
  EXPECT_EQ(covered, 10 * 12);  // columns 4..13, rows 2..13
}

TEST(UvRasterizer, ReproducesALinearFieldAndShowsVAtTheBottom) {
  const Mesh mesh = square_chart();
  const UvRasterizer raster(mesh, kSize);
  // Per-vertex value = f(u, v) at the vertex's UV, with f linear.
  const auto f = [](double u, double v) { return 0.3 * u - 0.7 * v + 0.1; };
  at::Tensor values = at::zeros({4, 1}, at::kDouble);
  for (int i = 0; i < 4; ++i) values[i][0] = f(mesh.uvs(3 - i, 0), mesh.uvs(3 - i, 1));
  const at::Tensor texture = raster.rasterize(values);
  EXPECT_EQ(texture.scalar_type(), at::kDouble);
  const auto t = texture.accessor<double, 3>();
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c)
      if (inside_chart(r, c)) EXPECT_NEAR(t[0][r][c], f(texel_u(c), texel_v(r)), 1e-6) << r << "," << c;
  // f decreases with v, so rows nearer the bottom (larger r, smaller v) are larger.
  EXPECT_GT(t[0][13][5], t[0][2][5]);
}

TEST(UvRasterizer, SampleLatentReadsBackWhatWasRasterised) {
  const Mesh mesh = square_chart();
  const UvRasterizer raster(mesh, kSize);
  at::Tensor values = at::zeros({4, 2});
  for (int i = 0; i < 4; ++i) {
    values[i][0] = mesh.uvs(3 - i, 0);
    values[i][1] = mesh.uvs(3 - i, 1);
  }
  const at::Tensor texture = raster.rasterize(values);  // channel k holds uv[k]
  // Points at least a texel inside the chart, where bilinear lookups see only covered texels.
  const at::Tensor uv = at::rand({40, 2}) * at::tensor({0.3f, 0.4f}) + at::tensor({0.3f, 0.4f});
  EXPECT_TRUE(at::allclose(sample_latent(texture, uv), uv, 1e-5, 1e-5));
}

TEST(UvRasterizer, GradientsReachTheVertexValues) {
  const UvRasterizer raster(square_chart(), kSize);
  const at::Tensor values = at::zeros({4, 3}).requires_grad_(true);
  raster.rasterize(values).sum().backward();
  // Each covered texel distributes weight 1 over its corners, per channel.
  EXPECT_NEAR(values.grad().sum().item<float>(), 3 * 120, 1e-3);
}

// square_chart() plus a later triangle (its own vertices) laid over the whole
// chart in UV, like ICT-FaceKit's eyeballs over its face.
Mesh chart_under_an_overlay() {
  Mesh mesh = square_chart();
  mesh.positions.conservativeResize(7, 3);
  mesh.positions.bottomRows(3) << 0, 0, 1, 1, 0, 1, 0, 1, 1;
  mesh.faces.conservativeResize(3, 3);
  mesh.faces.row(2) << 4, 5, 6;
  mesh.uvs.conservativeResize(7, 2);
  mesh.uvs.bottomRows(3) << 0.0f, 0.0f, 2.0f, 0.0f, 0.0f, 2.0f;
  mesh.uv_faces.conservativeResize(3, 3);
  mesh.uv_faces.row(2) << 4, 5, 6;
  return mesh;
}

TEST(UvRasterizer, DrawsOnlyTheGivenFacesSoAnOverlayHidesNothing) {
  const Mesh mesh = chart_under_an_overlay();
  at::Tensor values = at::zeros({7, 1});
  values.narrow(0, 0, 4).fill_(2.0);  // the chart's vertices; the overlay's stay 0
  const at::Tensor all = UvRasterizer(mesh, kSize).rasterize(values)[0];
  const at::Tensor chart_only = UvRasterizer(mesh, kSize, {0, 1}).rasterize(values)[0];
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c) {
      EXPECT_FLOAT_EQ(chart_only[r][c].item<float>(), inside_chart(r, c) ? 2.0f : 0.0f) << r << "," << c;
      EXPECT_FLOAT_EQ(all[r][c].item<float>(), 0.0f) << r << "," << c;  // the later overlay wins
    }
  EXPECT_THROW(UvRasterizer(mesh, kSize, {0, 3}), Error);
}

TEST(UvRasterizer, RejectsAMeshWithoutUvs) {
  Mesh mesh = square_chart();
  mesh.uvs.resize(0, 2);
  mesh.uv_faces.resize(0, 3);
  EXPECT_THROW(UvRasterizer(mesh, kSize), Error);
  EXPECT_THROW(UvRasterizer(square_chart(), 0), Error);
}

}  // namespace
}  // namespace tega::nn
