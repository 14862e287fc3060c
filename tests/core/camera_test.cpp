#include "tega/core/camera.h"

#include <gtest/gtest.h>

#include <random>

#include "tega/core/error.h"

namespace tega {
namespace {

// A studio camera with the distortion magnitudes of a real lens.
Camera studio_camera() {
  Camera c;
  c.name = "cam07";
  c.width = 2048;
  c.height = 1334;
  c.K << 1800.0, 0.0, 1020.3, 0.0, 1795.5, 660.7, 0.0, 0.0, 1.0;
  c.distortion = {-0.12, 0.08, 0.0012, -0.0008, -0.02};
  c.world_to_camera.R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1.0, -0.3).normalized()).toRotationMatrix();
  c.world_to_camera.t = Eigen::Vector3d(0.05, -0.12, 1.3);
  return c;
}

// World points the camera sees: pixels spread over the whole image (corners
// included) at depths from 0.3 to 3 m.
std::vector<Eigen::Vector3d> visible_points(const Camera& c, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.5, c.width - 0.5), v(-0.5, c.height - 0.5),
      depth(0.3, 3.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.push_back(c.unproject({u(rng), v(rng)}, depth(rng)));
  return points;
}

TEST(Camera, DistortMatchesOpenCvModel) {
  // Reference value of OpenCV's formula computed by hand for this point.
  const Eigen::Vector2d d = studio_camera().distort({0.3, -0.2});
  EXPECT_NEAR(d.x(), 0.295320418, 1e-15);
  EXPECT_NEAR(d.y(), -0.196793612, 1e-15);
}

TEST(Camera, UndistortInvertsDistort) {
  const Camera c = studio_camera();
  std::mt19937 rng(1);
  // Normalised coordinates beyond the image corners (|x| <= 0.57, |y| <= 0.37).
  std::uniform_real_distribution<double> x(-0.7, 0.7), y(-0.5, 0.5);
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector2d p(x(rng), y(rng));
    EXPECT_LT((c.undistort(c.distort(p)) - p).norm(), 1e-12) << p.transpose();
    EXPECT_LT((c.distort(c.undistort(p)) - p).norm(), 1e-12) << p.transpose();
  }
}

TEST(Camera, UnprojectInvertsProject) {
  const Camera c = studio_camera();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, c.width - 0.5), v(-0.5, c.height - 0.5),
      depth(0.3, 3.0);
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector2d pixel(u(rng), v(rng));
    const double z = depth(rng);
    const Eigen::Vector3d world = c.unproject(pixel, z);
    EXPECT_NEAR(c.world_to_camera.apply(world).z(), z, 1e-12);
    const auto back = c.project(world);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - pixel).norm(), 1e-8) << pixel.transpose();
  }
}

TEST(Camera, ProjectionJacobianMatchesCentralDifferences) {
  const Camera c = studio_camera();
  const double h = 1e-6;
  for (const Eigen::Vector3d& p : visible_points(c, 200)) {
    const Eigen::Matrix<double, 2, 3> analytic = c.projection_jacobian(p);
    Eigen::Matrix<double, 2, 3> numeric;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(k);
      numeric.col(k) = (*c.project(p + step) - *c.project(p - step)) / (2 * h);
    }
    EXPECT_LT((analytic - numeric).norm(), 1e-4 * numeric.norm()) << p.transpose();
  }
}

TEST(Camera, ProjectThenUnprojectRecoversWorldPoint) {
  const Camera c = studio_camera();
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> lateral(-0.4, 0.4), forward(0.5, 2.0);
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d in_camera(lateral(rng), lateral(rng) * 0.6, forward(rng));
    const Eigen::Vector3d world = c.world_to_camera.inverse().apply(in_camera);
    const auto pixel = c.project(world);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_LT((c.unproject(*pixel, in_camera.z()) - world).norm(), 1e-12);
  }
}

TEST(Camera, PointBehindOrBesideTheCameraHasNoProjection) {
  const Camera c = studio_camera();
  const RigidTransform camera_to_world = c.world_to_camera.inverse();
  EXPECT_FALSE(c.project(camera_to_world.apply({0.1, 0.2, -1.0})).has_value());
  EXPECT_FALSE(c.project(camera_to_world.apply({0.1, 0.2, 0.0})).has_value());
  EXPECT_FALSE(c.project(c.center()).has_value());
  EXPECT_TRUE(c.project(camera_to_world.apply({0.1, 0.2, 1e-3})).has_value());
}

TEST(Camera, CenterMapsToCameraOrigin) {
  const Camera c = studio_camera();
  EXPECT_LT(c.world_to_camera.apply(c.center()).norm(), 1e-15);
}

TEST(Camera, RayDirectionPointsAtTheProjectedPoint) {
  const Camera c = studio_camera();
  for (const Eigen::Vector3d& world : visible_points(c, 2000)) {
    const Eigen::Vector3d ray = c.ray_direction(*c.project(world));
    EXPECT_NEAR(ray.norm(), 1.0, 1e-15);
    EXPECT_LT((ray - (world - c.center()).normalized()).norm(), 1e-11);
  }
}

TEST(Camera, HasDistortionWhenAnyCoefficientIsSet) {
  Camera c;
  EXPECT_FALSE(c.has_distortion());
  for (size_t i = 0; i < 5; ++i) {
    c.distortion = {};
    c.distortion[i] = 1e-6;
    EXPECT_TRUE(c.has_distortion()) << "coefficient " << i;
  }
}

TEST(Camera, UndistortionMapsSampleWhereTheUndistortedRayProjects) {
  const Camera c = studio_camera().scaled(0.25);
  Camera pinhole = c;
  pinhole.distortion = {};
  const UndistortionMaps maps = c.undistortion_maps();
  ASSERT_EQ(maps.width, c.width);
  ASSERT_EQ(maps.height, c.height);
  ASSERT_EQ(maps.map_x.size(), static_cast<size_t>(c.width * c.height));
  ASSERT_EQ(maps.map_y.size(), maps.map_x.size());
  double largest_shift = 0;
  for (int v = 0; v < c.height; v += 7) {
    for (int u = 0; u < c.width; u += 5) {
      // The undistorted image is the pinhole camera's view: the map must point at
      // the captured pixel that sees the same ray.
      const Eigen::Vector3d world = pinhole.center() + pinhole.ray_direction({u, v});
      const Eigen::Vector2d captured = *c.project(world);
      const size_t i = static_cast<size_t>(v * c.width + u);
      EXPECT_NEAR(maps.map_x[i], captured.x(), 1e-3) << u << "," << v;
      EXPECT_NEAR(maps.map_y[i], captured.y(), 1e-3) << u << "," << v;
      largest_shift = std::max(largest_shift, (captured - Eigen::Vector2d(u, v)).norm());
    }
  }
  // The maps are not the identity: the corners move by several pixels.
  EXPECT_GT(largest_shift, 5.0);
}

TEST(Camera, UndistortionMapsOfAPinholeAreTheIdentity) {
  Camera c = studio_camera().scaled(0.125);
  c.distortion = {};
  const UndistortionMaps maps = c.undistortion_maps();
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      EXPECT_NEAR(maps.map_x[static_cast<size_t>(v * c.width + u)], u, 1e-4);
      EXPECT_NEAR(maps.map_y[static_cast<size_t>(v * c.width + u)], v, 1e-4);
    }
}

TEST(Camera, ScaledProjectsToTheResizedPixel) {
  const Camera c = studio_camera();
  for (double factor : {0.5, 0.25, 1.0 / 3.0, 2.0}) {
    const Camera s = c.scaled(factor);
    EXPECT_EQ(s.width, std::lround(c.width * factor));
    EXPECT_EQ(s.height, std::lround(c.height * factor));
    EXPECT_EQ(s.distortion, c.distortion);
    EXPECT_EQ(s.world_to_camera.matrix(), c.world_to_camera.matrix());
    for (const Eigen::Vector3d& world : visible_points(c, 500)) {
      const Eigen::Vector2d expected = factor * (*c.project(world) + Eigen::Vector2d(0.5, 0.5)) -
                                       Eigen::Vector2d(0.5, 0.5);
      EXPECT_LT((*s.project(world) - expected).norm(), 1e-9) << "factor " << factor;
    }
  }
}

TEST(Camera, ScaledKeepsTheImageCornerFixed) {
  // The outer corner of the top-left pixel is (-0.5, -0.5) at every resolution.
  const Camera c = studio_camera();
  const Camera half = c.scaled(0.5);
  const Eigen::Vector3d ray = c.ray_direction({-0.5, -0.5});
  EXPECT_LT((*half.project(c.center() + ray) - Eigen::Vector2d(-0.5, -0.5)).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(half.K(0, 0), 900.0);
  EXPECT_DOUBLE_EQ(half.K(0, 2), 0.5 * (1020.3 + 0.5) - 0.5);
  EXPECT_DOUBLE_EQ(half.K(1, 2), 0.5 * (660.7 + 0.5) - 0.5);
}

TEST(Camera, ScaledRejectsNonPositiveFactors) {
  const Camera c = studio_camera();
  EXPECT_THROW(c.scaled(0.0), Error);
  EXPECT_THROW(c.scaled(-0.5), Error);
}

}  // namespace
}  // namespace tega
