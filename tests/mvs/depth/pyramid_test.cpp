// Coarse to fine: the half-size view and the half-size estimate carried up.
#include <gtest/gtest.h>

#include "pyramid.h"

namespace tega::mvs::detail {
namespace {

StereoView view(int width, int height) {
  StereoView v;
  v.camera.name = "cam";
  v.camera.width = width;
  v.camera.height = height;
  v.camera.K << 100, 0, (width - 1) / 2.0, 0, 100, (height - 1) / 2.0, 0, 0, 1;
  v.grey = ImageF(width, height, 1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) v.grey.pixels[size_t(y) * width + x] = float(x + 10 * y) / 1000.0f;
  v.mask.assign(size_t(width) * height, 0);
  return v;
}

TEST(Pyramid, HalfSizeAveragesPixelsAndKeepsTheMaskWhereAnyPixelIsOn) {
  StereoView fine = view(8, 6);
  fine.mask[size_t(3) * 8 + 5] = 255;  // pixel (5, 3): coarse pixel (2, 1)
  const StereoView half = half_size(fine);
  ASSERT_EQ(half.camera.width, 4);
  ASSERT_EQ(half.camera.height, 3);
  EXPECT_FLOAT_EQ(half.grey.at(1, 2, 0), (fine.grey.at(2, 4, 0) + fine.grey.at(3, 4, 0) + fine.grey.at(2, 5, 0) +
                                          fine.grey.at(3, 5, 0)) / 4);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(half.mask[size_t(y) * 4 + x] != 0, x == 2 && y == 1) << x << "," << y;
  EXPECT_NEAR(half.camera.K(0, 0), 50, 1e-12);
}

TEST(Pyramid, UpsamplingKeepsTheCoarsePlanes) {
  StereoView fine = view(40, 30);
  std::fill(fine.mask.begin(), fine.mask.end(), 255);
  fine.mask[0] = 0;
  const Camera coarse_camera = fine.camera.scaled(0.5);
  DepthMap coarse(coarse_camera.width, coarse_camera.height);
  // One slanted plane, n.X = c, seen by every coarse pixel but one.
  Eigen::Vector3f n(0.2f, -0.1f, -1.0f);
  n.normalize();
  const float c = -1.5f;
  const Eigen::Matrix3d K_inverse = coarse_camera.K.inverse();
  for (int y = 0; y < coarse.height; ++y)
    for (int x = 0; x < coarse.width; ++x) {
      if (x == 7 && y == 7) continue;  // no estimate
      const Eigen::Vector3f ray = (K_inverse * Eigen::Vector3d(x, y, 1)).cast<float>();
      const size_t i = coarse.index(x, y);
      coarse.depth[i] = c / n.dot(ray);
      for (int k = 0; k < 3; ++k) coarse.normals[3 * i + k] = n[k];
      coarse.cost[i] = 0.25f;
    }
  Parameters p;
  p.depth_min = 1.0f;
  p.depth_max = 2.0f;
  const DepthMap up = upsampled(coarse, coarse_camera, fine, p);
  ASSERT_EQ(up.width, 40);
  ASSERT_EQ(up.height, 30);
  EXPECT_EQ(up.depth[0], 0.0f);  // outside the mask
  const Eigen::Matrix3d fine_K_inverse = fine.camera.K.inverse();
  int random = 0;
  for (int y = 0; y < up.height; ++y)
    for (int x = 0; x < up.width; ++x) {
      const size_t i = up.index(x, y);
      if (i == 0) continue;
      if (up.cost[i] == kMaxCost) {  // the coarse pixel without an estimate: a random start
        ++random;
        EXPECT_GE(up.depth[i], p.depth_min);
        EXPECT_LE(up.depth[i], p.depth_max);
        continue;
      }
      const Eigen::Vector3f ray = (fine_K_inverse * Eigen::Vector3d(x, y, 1)).cast<float>();
      EXPECT_NEAR(up.depth[i], c / n.dot(ray), 1e-5) << x << "," << y;
      EXPECT_NEAR(up.normals[3 * i + 2], n.z(), 1e-6);
      EXPECT_EQ(up.cost[i], 0.25f);
    }
  EXPECT_EQ(random, 4);  // the 2 x 2 fine pixels of coarse pixel (7, 7)
}

}  // namespace
}  // namespace tega::mvs::detail
