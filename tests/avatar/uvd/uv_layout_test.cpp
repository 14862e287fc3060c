#include "tega/uvd/uv_layout.h"

#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/uvd/uv_lookup.h"
#include "test_support.h"
#include "uvd_test_meshes.h"

namespace tega::uvd {
namespace {

// A square of side `side` metres at height z whose UVs fill the square at
// `uv` with side `uv_side`.
struct Square {
  double side, z;
  Eigen::Vector2f uv;
  double uv_side;
};

// Squares of two triangles each (square i: triangles 2i, 2i + 1), with UV
// entries of their own.
Mesh squares(const std::vector<Square>& list) {
  Mesh m;
  const auto n = static_cast<Eigen::Index>(list.size());
  m.positions.resize(4 * n, 3);
  m.uvs.resize(4 * n, 2);
  m.faces.resize(2 * n, 3);
  m.uv_faces.resize(2 * n, 3);
  const float corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (Eigen::Index i = 0; i < n; ++i) {
    const Square& q = list[static_cast<size_t>(i)];
    for (int c = 0; c < 4; ++c) {
      m.positions.row(4 * i + c) << corners[c][0] * q.side, corners[c][1] * q.side, q.z;
      m.uvs.row(4 * i + c) << q.uv.x() + corners[c][0] * q.uv_side, q.uv.y() + corners[c][1] * q.uv_side;
    }
    const auto v = static_cast<int32_t>(4 * i);
    m.faces.row(2 * i) << v, v + 1, v + 2;
    m.faces.row(2 * i + 1) << v, v + 2, v + 3;
    m.uv_faces.row(2 * i) = m.faces.row(2 * i);
    m.uv_faces.row(2 * i + 1) = m.faces.row(2 * i + 1);
  }
  return m;
}

// A 2 m square (triangles 0, 1) filling UV [0,1]², and a 1 m square
// (triangles 2, 3) on top of it in [0.75,1]², at a quarter of its UV density,
// sharing the UV entry (1, 1) with it.
Mesh overlapping_squares() {
  Mesh m = squares({{2, 0, {0, 0}, 1}, {1, 1, {0.75f, 0.75f}, 0.25}});
  m.uv_faces(2, 2) = m.uv_faces(3, 1) = 2;
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
  // In the tile right of the rest, a sixteenth of a tile in, the shape kept.
  for (int f = 2; f < 4; ++f)
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(laid.uvs(laid.uv_faces(f, k), 0), 1.0 + 1.0 / 16 - 1e-6);
      EXPECT_GE(laid.uvs(laid.uv_faces(f, k), 1), 1.0 / 16 - 1e-6);
    }
  EXPECT_NEAR(test::uv_area(laid, 2), 0.125, 1e-6);
  EXPECT_NEAR(test::uv_area(laid, 3), 0.125, 1e-6);
}

// Mirror charts: a part of two islands on top of each other and of the rest
// (as ICT-FaceKit's left and right eyeballs) gets one place per island.
TEST(UvLayout, EveryIslandOfThePartGetsAPlaceOfItsOwn) {
  const Mesh mesh = squares({{1, 0, {0, 0}, 1}, {0.5, 1, {0.25f, 0.25f}, 0.5}, {0.5, 2, {0.25f, 0.25f}, 0.5}});
  EXPECT_EQ(uv_islands(mesh, {5, 2, 3, 4}), (std::vector<std::vector<int32_t>>{{2, 3}, {4, 5}}));
  const Mesh laid = with_part_laid_apart(mesh, {2, 3, 4, 5});
  const at::Tensor after = UvTriangleLookup(laid).lookup(centroid_uvs(laid, {0, 1, 2, 3, 4, 5})).triangle;
  for (int64_t f = 0; f < 6; ++f) EXPECT_EQ(after[f].item<int64_t>(), f);
  EXPECT_NEAR(uv_per_world_area(laid, {2, 3, 4, 5}), uv_per_world_area(laid, {0, 1}), 1e-6);
}

// An island larger than a tile at the rest's density is scaled down to fit one.
TEST(UvLayout, AnIslandTooLargeForATileIsScaledToFitOne) {
  const Mesh mesh = squares({{1, 0, {0, 0}, 1}, {2, 1, {0, 0}, 1}});
  const Mesh laid = with_part_laid_apart(mesh, {2, 3});
  for (int f = 2; f < 4; ++f)
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 2; ++axis) {
        const double x = laid.uvs(laid.uv_faces(f, k), axis) - (axis == 0 ? 1.0 : 0.0);
        EXPECT_GE(x, 1.0 / 16 - 1e-6);
        EXPECT_LE(x, 1 - 1.0 / 16 + 1e-6);
      }
}

// A multi-tile (UDIM) layout: tiles (0,0), (1,0), (3,0) and (0,1) become the
// cells of a 2 x 2 grid, each scaled alike, every uv still naming one point.
TEST(UvLayout, AMultiTileLayoutIsPackedIntoTheUnitSquare) {
  const Mesh mesh = squares({{1, 0, {0.1f, 0.1f}, 0.8}, {1, 1, {1.2f, 0.3f}, 0.5}, {1, 2, {3.0f, 0.0f}, 1.0},
                             {1, 3, {0.5f, 1.25f}, 0.25}});
  const Mesh packed = packed_in_unit_square(mesh);
  EXPECT_EQ(packed.faces, mesh.faces);
  EXPECT_EQ(packed.uv_faces, mesh.uv_faces);
  EXPECT_GE(packed.uvs.minCoeff(), 0.0f);
  EXPECT_LE(packed.uvs.maxCoeff(), 1.0f);
  const double scale = 1 / (2 * (1 + 1.0 / 32));
  for (int f = 0; f < 8; ++f) EXPECT_NEAR(test::uv_area(packed, f), scale * scale * test::uv_area(mesh, f), 1e-6);
  const at::Tensor triangle = UvTriangleLookup(packed).lookup(centroid_uvs(packed, {0, 1, 2, 3, 4, 5, 6, 7})).triangle;
  for (int64_t f = 0; f < 8; ++f) EXPECT_EQ(triangle[f].item<int64_t>(), f);
  // In order of v then u: tile (0,0) takes the first cell, bottom left, its
  // shape within the tile kept; tile (0,1), the last, the top right one.
  const double half_gap = 1.0 / 64, cell = 1 + 1.0 / 32;
  EXPECT_NEAR(packed.uvs(0, 0), scale * (half_gap + 0.1), 1e-6);
  EXPECT_NEAR(packed.uvs(0, 1), scale * (half_gap + 0.1), 1e-6);
  EXPECT_NEAR(packed.uvs(12, 0), scale * (cell + half_gap + 0.5), 1e-6);
  EXPECT_NEAR(packed.uvs(12, 1), scale * (cell + half_gap + 0.25), 1e-6);
}

TEST(UvLayout, ALayoutInTheUnitSquareStaysAsItIs) {
  const Mesh mesh = test::seamed_mesh();
  const Mesh packed = packed_in_unit_square(mesh);
  EXPECT_EQ(packed.uvs, mesh.uvs);
  EXPECT_EQ(packed.uv_faces, mesh.uv_faces);
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

TEST(UvLayout, IctFaceKitsEyeballChartsGetGaussiansByTheirAreaAlsoPacked) {
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

  // The polygon of the triangle each of 50000 uniform UV samples lands on.
  auto sampled_polygons = [&](const Mesh& m) {
    const UvTriangleLookup lookup(m);
    at::Tensor polygon = at::empty({m.num_faces()}, at::kLong);
    for (int f = 0; f < m.num_faces(); ++f) polygon[f] = full.triangle_polygon[kept[f]];
    return polygon.index_select(0, lookup.lookup(lookup.sample_uniform(50000, 3)).triangle);
  };
  auto sample_share = [](const at::Tensor& polygons, int first, int last) {
    return ((polygons >= first) & (polygons <= last)).to(at::kDouble).mean().item<double>();
  };
  auto area_share = [&](int first, int last) {
    double part = 0, total = 0;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3f a = mesh.positions.row(mesh.faces(f, 0)), b = mesh.positions.row(mesh.faces(f, 1)),
                            c = mesh.positions.row(mesh.faces(f, 2));
      const double area = 0.5 * (b - a).cross(c - a).norm();
      total += area;
      if (full.triangle_polygon[kept[f]] >= first && full.triangle_polygon[kept[f]] <= last) part += area;
    }
    return part / total;
  };
  // Laid over the face, the eyeballs get under 1 % of the samples, not their share.
  EXPECT_LT(sample_share(sampled_polygons(mesh), kEyeballFirst, kEyeballLast),
            0.5 * area_share(kEyeballFirst, kEyeballLast));
  // Laid apart, each of the four charts on top of each other (sclera and
  // iris, left and right: the README's polygon ranges) gets its share of the
  // eyeballs' (their UV areas keep their proportions); packed into the unit
  // square too, where the face keeps its share.
  const Mesh laid = with_part_laid_apart(mesh, eyeballs);
  const Mesh packed = packed_in_unit_square(laid);
  for (int f = 0; f < packed.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f uv = packed.uvs.row(packed.uv_faces(f, k));
      ASSERT_TRUE(uv.minCoeff() >= 0 && uv.maxCoeff() <= 1) << "triangle " << f << " uv " << uv.transpose();
    }
  auto uv_area_of = [&](int first, int last) {
    double area = 0;
    for (int f = 0; f < mesh.num_faces(); ++f)
      if (full.triangle_polygon[kept[f]] >= first && full.triangle_polygon[kept[f]] <= last) area += test::uv_area(mesh, f);
    return area;
  };
  const at::Tensor on_laid = sampled_polygons(laid), on_packed = sampled_polygons(packed);
  const double eyeballs_share = area_share(kEyeballFirst, kEyeballLast);
  const double eyeballs_uv = uv_area_of(kEyeballFirst, kEyeballLast);
  for (const auto& [first, last] : {std::pair{21496, 22295}, {22296, 23093}, {23094, 23893}, {23894, 24691}}) {
    const double expected = eyeballs_share * uv_area_of(first, last) / eyeballs_uv;
    EXPECT_NEAR(sample_share(on_laid, first, last), expected, 0.1 * expected) << "polygons " << first << ".." << last;
    EXPECT_NEAR(sample_share(on_packed, first, last), expected, 0.1 * expected) << "polygons " << first << ".." << last;
  }
  const double face = sample_share(on_laid, 0, 9229);
  EXPECT_NEAR(sample_share(on_packed, 0, 9229), face, 0.05 * face);
}

}  // namespace
}  // namespace tega::uvd
