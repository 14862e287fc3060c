#include "tega/uvd/uv_layout.h"

#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/uvd/uv_lookup.h"
#include "test_support.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

// Two unit squares 1 m apart: the first (triangles 0, 1) fills UV [0,1]²,
// the second (triangles 2, 3) lies on top of it in [0.5,1]², at a quarter of
// its UV density, sharing the UV entry (1, 1) with it.
Mesh overlapping_squares() {
  Mesh m;
  m.positions.resize(8, 3);
  m.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  m.faces.resize(4, 3);
  m.faces << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7;
  m.uvs.resize(7, 2);
  m.uvs << 0, 0, 1, 0, 1, 1, 0, 1,  //
      0.5, 0.5, 1, 0.5, 0.5, 1;
  m.uv_faces.resize(4, 3);
  m.uv_faces << 0, 1, 2, 0, 2, 3, 4, 5, 2, 4, 2, 6;
  return m;
}

at::Tensor centroid_uvs(const Mesh& m, const std::vector<int>& faces) {
  at::Tensor out = at::zeros({static_cast<int64_t>(faces.size()), 2}, at::kDouble);
  for (size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      out[static_cast<int64_t>(i)][0] += m.uvs(m.uv_faces(faces[i], k), 0) / 3.0;
      out[static_cast<int64_t>(i)][1] += m.uvs(m.uv_faces(faces[i], k), 1) / 3.0;
    }
  return out;
}

double uv_per_world_area(const Mesh& m, const std::vector<int>& faces) {
  double uv = 0, world = 0;
  for (int f : faces) {
    uv += test::uv_area(m, f);
    const Eigen::Vector3f a = m.positions.row(m.faces(f, 0)), b = m.positions.row(m.faces(f, 1)),
                          c = m.positions.row(m.faces(f, 2));
    world += 0.5 * (b - a).cross(c - a).norm();
  }
  return uv / world;
}

TEST(UvLayout, AnOverlappingPartGetsAnIslandOfItsOwnAtTheRestsDensity) {
  const Mesh mesh = overlapping_squares();
  // As laid out, the part's points are answered with the square under them.
  const at::Tensor before = UvTriangleLookup(mesh).lookup(centroid_uvs(mesh, {2, 3})).triangle;
  EXPECT_TRUE((before < 2).any().item<bool>());

  const Mesh laid = with_part_laid_apart(mesh, {2, 3});
  EXPECT_EQ(laid.positions, mesh.positions);
  EXPECT_EQ(laid.faces, mesh.faces);
  for (int f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(laid.uvs.row(laid.uv_faces(f, k)), mesh.uvs.row(mesh.uv_faces(f, k)));
  // Every uv now names one point: the part's own triangles answer for it.
  const at::Tensor after = UvTriangleLookup(laid).lookup(centroid_uvs(laid, {2, 3})).triangle;
  EXPECT_EQ(after[0].item<int64_t>(), 2);
  EXPECT_EQ(after[1].item<int64_t>(), 3);
  EXPECT_NEAR(uv_per_world_area(laid, {2, 3}), uv_per_world_area(laid, {0, 1}), 1e-6);
  // Right of the rest, a sixteenth of its size away, the shape kept.
  for (int f = 2; f < 4; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_GE(laid.uvs(laid.uv_faces(f, k), 0), 1.0 + 1.0 / 16 - 1e-6);
  EXPECT_NEAR(test::uv_area(laid, 2), 0.5, 1e-6);
  EXPECT_NEAR(test::uv_area(laid, 3), 0.5, 1e-6);
}

TEST(UvLayout, APartWithItsOwnIslandStaysWhereItIs) {
  const Mesh mesh = test::seamed_mesh();
  std::vector<int32_t> cap;  // the fan on its own UV disc
  for (int f = 6 * 12 * 2; f < 6 * 12 * 2 + 12; ++f) cap.push_back(f);
  const Mesh laid = with_part_laid_apart(mesh, cap);
  EXPECT_EQ(laid.uvs, mesh.uvs);
  EXPECT_EQ(laid.uv_faces, mesh.uv_faces);
}

TEST(UvLayout, RefusesAFaceOutOfRangeAndAMeshWithoutUvs) {
  Mesh mesh = overlapping_squares();
  EXPECT_THROW(with_part_laid_apart(mesh, {4}), tega::Error);
  mesh.uvs.resize(0, 2);
  mesh.uv_faces.resize(0, 3);
  EXPECT_THROW(with_part_laid_apart(mesh, {2}), tega::Error);
}

TEST(UvLayout, IctFaceKitsEyeballsGetGaussiansByTheirArea) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  at::set_num_threads(2);
  const Mesh full = read_obj(ict / "generic_neutral_mesh.obj");
  // The face, head, mouth and eyeballs: polygons up to the last eyeball one
  // (ICT-FaceKit's README; the eye blend and occlusion overlays follow).
  constexpr int kEyeballFirst = 21496, kEyeballLast = 24691;
  Mesh mesh = full;
  std::vector<int32_t> kept, eyeballs;
  for (int f = 0; f < full.num_faces(); ++f)
    if (full.triangle_polygon[f] <= kEyeballLast) {
      if (full.triangle_polygon[f] >= kEyeballFirst) eyeballs.push_back(static_cast<int32_t>(kept.size()));
      kept.push_back(f);
    }
  mesh.faces.resize(static_cast<Eigen::Index>(kept.size()), 3);
  mesh.uv_faces.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) {
    mesh.faces.row(static_cast<Eigen::Index>(i)) = full.faces.row(kept[i]);
    mesh.uv_faces.row(static_cast<Eigen::Index>(i)) = full.uv_faces.row(kept[i]);
  }
  mesh.triangle_polygon.clear();

  auto eyeball_share = [&](const Mesh& m) {
    const UvTriangleLookup lookup(m);
    at::Tensor on_eyeball = at::zeros({m.num_faces()}, at::kBool);
    for (int32_t f : eyeballs) on_eyeball[f] = true;
    const at::Tensor triangle = lookup.lookup(lookup.sample_uniform(50000, 3)).triangle;
    return on_eyeball.index_select(0, triangle).to(at::kDouble).mean().item<double>();
  };
  double eyeball_area = 0, total_area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3f a = mesh.positions.row(mesh.faces(f, 0)), b = mesh.positions.row(mesh.faces(f, 1)),
                          c = mesh.positions.row(mesh.faces(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    total_area += area;
    if (full.triangle_polygon[kept[f]] >= kEyeballFirst) eyeball_area += area;
  }
  const double expected = eyeball_area / total_area;
  // Laid over the face, the eyeballs get under 1 % of the samples, not their share.
  EXPECT_LT(eyeball_share(mesh), 0.5 * expected);
  EXPECT_NEAR(eyeball_share(with_part_laid_apart(mesh, eyeballs)), expected, 0.1 * expected);
}

}  // namespace
}  // namespace tega::uvd
