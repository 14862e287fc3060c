#include <gtest/gtest.h>

#include "tega/synth/rasterizer.h"

namespace tega::synth {
namespace {

Camera pinhole(int w, int h) {
  Camera c;
  c.name = "test";
  c.width = w;
  c.height = h;
  c.K << 100, 0, (w - 1) / 2.0, 0, 100, (h - 1) / 2.0, 0, 0, 1;
  return c;  // at the origin, looking along +z
}

// A square of half-size `r` at depth `z` facing the camera (counter-clockwise
// as the camera sees it when `front`).
struct Square {
  Vertices positions{4, 3}, normals{4, 3};
  Triangles faces{2, 3};
  Square(double r, double z, bool front) {
    positions << -r, -r, z, r, -r, z, r, r, z, -r, r, z;  // camera y points down: rows 0,1 are on top
    normals.rowwise() = Eigen::RowVector3f(0, 0, -1);
    if (front) faces << 0, 3, 2, 0, 2, 1;
    else faces << 0, 2, 3, 0, 1, 2;
  }
  Surface surface(const Eigen::Vector3f& colour) const {
    return {&positions, &normals, &faces, nullptr, nullptr, [colour](const SurfaceSample&) { return colour; }};
  }
};

TEST(Rasterizer, CoverageIsTheAreaAndEdgesAreAntialiased) {
  const Camera cam = pinhole(64, 48);
  // Half-size 0.1 m at 1 m with f = 100 px: 20 x 20 px, edges through pixel centres +- 0.5.
  const Square sq(0.1, 1.0, true);
  const ImageF img = rasterize(cam, {sq.surface({1, 0, 0})}, 4);
  double area = 0;
  bool partial = false;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      area += img.at(x, y, 3);
      partial |= img.at(x, y, 3) > 0.05 && img.at(x, y, 3) < 0.95;
      EXPECT_NEAR(img.at(x, y, 0), img.at(x, y, 3), 1e-6);  // premultiplied red
    }
  EXPECT_NEAR(area, 400.0, 4.0);
  EXPECT_FALSE(partial) << "edges through pixel boundaries leave no partly covered pixel";
  const Square shifted(0.1025, 1.0, true);  // edges a quarter pixel into the border pixels
  const ImageF img2 = rasterize(cam, {shifted.surface({1, 0, 0})}, 4);
  EXPECT_NEAR(img2.at(31 - 10, 23, 3), 0.25f, 0.01f);
}

TEST(Rasterizer, CullsBackFacesAndKeepsTheNearestSurface) {
  const Camera cam = pinhole(32, 32);
  const Square back_facing(0.05, 1.0, false);
  const ImageF culled = rasterize(cam, {back_facing.surface({1, 1, 1})}, 2);
  EXPECT_EQ(culled.at(16, 16, 3), 0.0f);

  const Square near(0.05, 1.0, true), far(0.1, 2.0, true);
  const ImageF img = rasterize(cam, {far.surface({0, 0, 1}), near.surface({1, 0, 0})}, 2);
  EXPECT_EQ(img.at(16, 16, 0), 1.0f);  // the near red square wins whatever the order
  EXPECT_EQ(img.at(16, 16, 2), 0.0f);
}

TEST(Rasterizer, FollowsTheLensDistortion) {
  Camera cam = pinhole(64, 64);
  const Square sq(0.25, 1.0, true);  // corners at normalised radius 0.35
  cam.distortion = {-0.2, 0, 0, 0, 0};
  const ImageF img = rasterize(cam, {sq.surface({1, 1, 1})}, 2);
  // Barrel distortion pulls the corner in: the pixel at the true projection of the corner region is covered.
  const auto corner = cam.project(Eigen::Vector3d(0.24, 0.24, 1.0));
  ASSERT_TRUE(corner);
  EXPECT_GT(img.at(int(std::lround(corner->x())), int(std::lround(corner->y())), 3), 0.9f);
  const auto outside = cam.project(Eigen::Vector3d(0.27, 0.27, 1.0));
  EXPECT_LT(img.at(int(std::lround(outside->x())), int(std::lround(outside->y())), 3), 0.1f);
}

}  // namespace
}  // namespace tega::synth
