#include "tega/core/silhouette.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tega {
namespace {

// A tube of radius 5 cm from y = -0.1 to 0.1 m with a closed top and an open
// bottom (a neck's cut), its triangles wound counter-clockwise seen from
// outside, like a head model's.
Mesh open_tube() {
  constexpr int kSides = 32;
  Mesh tube;
  tube.positions.resize(2 * kSides + 1, 3);
  for (int i = 0; i < kSides; ++i) {
    const double a = 2 * M_PI * i / kSides;
    const float x = float(0.05 * std::cos(a)), z = float(0.05 * std::sin(a));
    tube.positions.row(i) << x, -0.1f, z;           // bottom rim
    tube.positions.row(kSides + i) << x, 0.1f, z;  // top rim
  }
  tube.positions.row(2 * kSides) << 0, 0.1f, 0;  // top centre
  tube.faces.resize(3 * kSides, 3);
  for (int i = 0; i < kSides; ++i) {
    const int j = (i + 1) % kSides;
    tube.faces.row(3 * i) << i, kSides + i, j;
    tube.faces.row(3 * i + 1) << j, kSides + i, kSides + j;
    tube.faces.row(3 * i + 2) << kSides + i, 2 * kSides, kSides + j;
  }
  return tube;
}

// A camera 0.6 m below the tube and 0.2 m to its side, looking at its open end.
Camera camera_below() {
  Camera c;
  c.name = "below";
  c.width = 200;
  c.height = 200;
  c.K << 300, 0, 99.5, 0, 300, 99.5, 0, 0, 1;
  const Eigen::Vector3d centre(0, -0.6, 0.2), target(0, -0.1, 0);
  const Eigen::Vector3d forward = (target - centre).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitX()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  c.world_to_camera.R.row(0) = right.transpose();
  c.world_to_camera.R.row(1) = down.transpose();
  c.world_to_camera.R.row(2) = forward.transpose();
  c.world_to_camera.t = -c.world_to_camera.R * centre;
  return c;
}

TEST(MeshSilhouette, TrianglesFacingTheCameraLeaveAnOpenCutSeeThrough) {
  const Mesh tube = open_tube();
  const Camera camera = camera_below();
  const auto opening = camera.project(Eigen::Vector3d(0, -0.1, 0));
  ASSERT_TRUE(opening);
  const int x = int(std::lround(opening->x())), y = int(std::lround(opening->y()));
  const auto covered = [](const Image8& mask) {
    int count = 0;
    for (uint8_t p : mask.pixels) count += p == 255;
    return count;
  };

  const Image8 all = mesh_silhouette(camera, tube.positions, tube.faces);
  const Image8 facing = mesh_silhouette(camera, tube.positions, tube.faces, Facing::toward_camera);
  EXPECT_EQ(all.at(x, y, 0), 255) << "every triangle: the tube's inside fills its opening";
  EXPECT_EQ(facing.at(x, y, 0), 0) << "the outward sides only: the opening shows what lies behind it";
  // The outer wall is there either way, and nothing the facing triangles
  // cover lies outside the whole silhouette.
  EXPECT_GT(covered(facing), covered(all) / 4);
  for (size_t i = 0; i < all.pixels.size(); ++i)
    if (facing.pixels[i] == 255) ASSERT_EQ(all.pixels[i], 255) << "pixel " << i;
}

}  // namespace
}  // namespace tega
