#include "tega/core/undistort.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tega/core/downsample.h"
#include "tega/core/error.h"

namespace tega {
namespace {

// A small camera with a strong pincushion distortion: image corners move by
// several pixels, so an image left distorted differs clearly from a pinhole's.
Camera distorted_camera() {
  Camera c;
  c.name = "cam";
  c.width = 160;
  c.height = 120;
  c.K << 150.0, 0.0, 81.3, 0.0, 151.0, 58.7, 0.0, 0.0, 1.0;
  c.distortion = {0.25, 0.05, 0.002, -0.003, 0.01};
  return c;
}

// A smooth pattern on the plane of undistorted normalised coordinates (x/z,
// y/z): what a pinhole camera with the same K would see of a painted plane.
double scene(const Eigen::Vector2d& normalised) {
  return 0.5 + 0.4 * std::sin(2 * M_PI * normalised.x() / 0.17) * std::cos(2 * M_PI * normalised.y() / 0.13);
}

Eigen::Vector2d pixel_to_normalised(const Camera& c, double u, double v) {
  return {(u - c.K(0, 2)) / c.K(0, 0), (v - c.K(1, 2)) / c.K(1, 1)};
}

// Renders the scene as `camera` sees it: each pixel looks along the ray whose
// distorted normalised coordinates it has.
Image8 render(const Camera& camera) {
  Image8 image(camera.width, camera.height, 3);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double value = scene(camera.undistort(pixel_to_normalised(camera, u, v)));
      for (int c = 0; c < 3; ++c) image.at(u, v, c) = static_cast<uint8_t>(std::lround(255 * value));
    }
  }
  return image;
}

// Mean absolute difference over the pixels where `mask` (channel 0) is non-zero.
double mean_difference(const Image8& a, const Image8& b, const Image8& mask) {
  double sum = 0;
  int count = 0;
  for (int v = 0; v < a.height; ++v) {
    for (int u = 0; u < a.width; ++u) {
      if (mask.at(u, v, 0) == 0) continue;
      sum += std::abs(static_cast<int>(a.at(u, v, 0)) - static_cast<int>(b.at(u, v, 0)));
      ++count;
    }
  }
  return sum / count;
}

TEST(Undistort, MatchesThePinholeRenderingOfTheSameScene) {
  const Camera camera = distorted_camera();
  const Image8 captured = render(camera);
  const Image8 pinhole = render(without_distortion(camera));
  const Image8 undistorted = undistort_image(captured, camera);
  ASSERT_EQ(undistorted.width, camera.width);
  ASSERT_EQ(undistorted.height, camera.height);
  ASSERT_EQ(undistorted.channels, 3);

  // Pincushion distortion: the pinhole's corners lie outside the captured
  // image and come out black; everything else is the pinhole's view up to the blur
  // of bilinear resampling.
  Image8 inside(camera.width, camera.height, 1, 0);
  int outside = 0, outside_black = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d p = camera.K * camera.distort(pixel_to_normalised(camera, u, v)).homogeneous();
      const bool covered = p.x() >= 0 && p.x() <= camera.width - 1 && p.y() >= 0 && p.y() <= camera.height - 1;
      inside.at(u, v, 0) = covered ? 1 : 0;
      if (p.x() < -0.5 || p.x() > camera.width - 0.5 || p.y() < -0.5 || p.y() > camera.height - 0.5) {
        ++outside;
        outside_black += undistorted.at(u, v, 0) == 0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(outside, 0);
  EXPECT_EQ(outside_black, outside);
  EXPECT_LT(mean_difference(undistorted, pinhole, inside), 2.5);
  // The check has teeth: the captured image itself is far from the pinhole's.
  EXPECT_GT(mean_difference(captured, pinhole, inside), 20.0);
}

TEST(Undistort, InOnePassWithDownsamplingEqualsTheTwoSteps) {
  const Camera camera = distorted_camera();
  const Image8 captured = render(camera);
  const UndistortionMaps maps = camera.undistortion_maps();
  for (const int factor : {1, 2, 4}) {
    const Image8 one_pass = undistort_image(captured, maps, factor);
    const Image8 two_steps = box_downsample(undistort_image(captured, maps), factor);
    EXPECT_EQ(one_pass.width, two_steps.width);
    EXPECT_EQ(one_pass.pixels, two_steps.pixels) << "factor " << factor;
  }
  EXPECT_THROW(undistort_image(captured, maps, 7), Error);
}

TEST(Undistort, APointLandsWherePinholeProjectionPutsIt) {
  Camera camera = distorted_camera();
  camera.world_to_camera.t = {0.01, -0.02, 1.0};
  const Eigen::Vector3d point(0.41, 0.32, 0.0);  // near the bottom-right corner, where distortion is strong
  const Eigen::Vector2d distorted = *camera.project(point);
  const Eigen::Vector2d pinhole = *without_distortion(camera).project(point);
  ASSERT_GT((distorted - pinhole).norm(), 3.0);

  // A bright 3x3 block centred on the distorted projection; its centroid after
  // undistortion lies at the pinhole projection.
  Image8 captured(camera.width, camera.height, 1, 0);
  const int cu = static_cast<int>(std::lround(distorted.x())), cv = static_cast<int>(std::lround(distorted.y()));
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) captured.at(cu + du, cv + dv, 0) = 255;
  const Image8 undistorted = undistort_image(captured, camera);
  double sum = 0, su = 0, sv = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      sum += undistorted.at(u, v, 0);
      su += u * undistorted.at(u, v, 0);
      sv += v * undistorted.at(u, v, 0);
    }
  }
  ASSERT_GT(sum, 0);
  const Eigen::Vector2d expected = pinhole + (Eigen::Vector2d(cu, cv) - distorted);  // the block's rounding
  EXPECT_NEAR(su / sum, expected.x(), 0.5);
  EXPECT_NEAR(sv / sum, expected.y(), 0.5);
}

TEST(Undistort, WithoutDistortionKeepsEverythingElse) {
  const Camera camera = distorted_camera();
  const Camera pinhole = without_distortion(camera);
  EXPECT_FALSE(pinhole.has_distortion());
  EXPECT_EQ(pinhole.K, camera.K);
  EXPECT_EQ(pinhole.width, camera.width);
  EXPECT_EQ(pinhole.name, camera.name);
}

TEST(Undistort, AnImageOfTheWrongSizeIsRefused) {
  const Image8 wrong(10, 10, 3);
  EXPECT_THROW(undistort_image(wrong, distorted_camera()), Error);
}

}  // namespace
}  // namespace tega
