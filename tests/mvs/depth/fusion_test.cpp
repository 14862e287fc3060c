// Fusion of exact depth maps of a sphere: every point on the sphere, outliers
// that no other view confirms dropped.
#include <gtest/gtest.h>

#include <random>

#include "tega/core/error.h"
#include "tega/mvs/fusion.h"

namespace tega::mvs {
namespace {

constexpr double kRadius = 0.1;

// A camera at distance 0.6 from the origin, looking at it, from azimuth `angle`.
Camera looking_at_origin(const std::string& name, double angle_deg) {
  Camera c;
  c.name = name;
  c.width = 96;
  c.height = 80;
  c.K << 300, 0, 47.5, 0, 300, 39.5, 0, 0, 1;
  const double a = angle_deg * M_PI / 180;
  const Eigen::Vector3d centre(0.6 * std::sin(a), 0.05, -0.6 * std::cos(a));
  const Eigen::Vector3d z = (-centre).normalized(), x = Eigen::Vector3d::UnitY().cross(z).normalized(), y = z.cross(x);
  c.world_to_camera.R.row(0) = x;
  c.world_to_camera.R.row(1) = y;
  c.world_to_camera.R.row(2) = z;
  c.world_to_camera.t = -c.world_to_camera.R * centre;
  return c;
}

// The exact depth and normal of the sphere at every pixel.
DepthMap sphere_depth(const Camera& c) {
  DepthMap map(c.width, c.height);
  const Eigen::Vector3d o = c.world_to_camera.t;  // the sphere's centre in camera coordinates
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const Eigen::Vector3d ray = c.K.inverse() * Eigen::Vector3d(x, y, 1);  // z = 1
      const double a = ray.squaredNorm(), b = -2 * ray.dot(o), cc = o.squaredNorm() - kRadius * kRadius;
      const double disc = b * b - 4 * a * cc;
      if (disc < 0) continue;
      const double depth = (-b - std::sqrt(disc)) / (2 * a);
      const Eigen::Vector3d normal = (depth * ray - o).normalized();
      const size_t i = map.index(x, y);
      map.depth[i] = float(depth);
      for (int k = 0; k < 3; ++k) map.normals[3 * i + k] = float(normal(k));
      map.cost[i] = 0;
    }
  return map;
}

struct Scene {
  std::vector<StereoView> views;
  std::vector<DepthMap> maps;
  std::vector<int> map_views;
};

Scene sphere_scene() {
  Scene s;
  for (int k = 0; k < 5; ++k) {
    StereoView view;
    view.camera = looking_at_origin("cam" + std::to_string(k), -30 + 15 * k);
    view.grey = ImageF(view.camera.width, view.camera.height, 1, 0.5f);
    s.maps.push_back(sphere_depth(view.camera));
    s.views.push_back(std::move(view));
    s.map_views.push_back(k);
  }
  return s;
}

TEST(Fusion, PointsLieOnTheSurfaceWithOutwardNormals) {
  const Scene s = sphere_scene();
  FusionOptions o;
  o.voxel_size_m = 0;
  const OrientedPointCloud cloud = fuse_depth_maps(s.views, s.map_views, s.maps, o);
  ASSERT_GT(cloud.size(), 5000);
  for (int i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.points.row(i).cast<double>();
    ASSERT_NEAR(p.norm(), kRadius, 2e-4);
    ASSERT_GT(cloud.normals.row(i).cast<double>().dot(p.normalized()), 0.99);
  }
  EXPECT_EQ(cloud.colors.rows(), cloud.size());
  EXPECT_EQ(int(cloud.colors(0, 0)), 128);  // grey 0.5
}

TEST(Fusion, UnconfirmedDepthsAreDropped) {
  Scene s = sphere_scene();
  // A patch of view 2 pushed 3 cm back: no other view sees anything there.
  for (int y = 30; y < 50; ++y)
    for (int x = 38; x < 58; ++x) s.maps[2].depth[s.maps[2].index(x, y)] += 0.03f;
  FusionOptions o;
  o.voxel_size_m = 0;
  const OrientedPointCloud cloud = fuse_depth_maps(s.views, s.map_views, s.maps, o);
  for (int i = 0; i < cloud.size(); ++i) ASSERT_NEAR(cloud.points.row(i).cast<double>().norm(), kRadius, 2e-4);
  o.min_consistent_views = 5;  // more than the other views there are
  EXPECT_EQ(fuse_depth_maps(s.views, s.map_views, s.maps, o).size(), 0);
}

TEST(Fusion, VoxelsMergePoints) {
  const Scene s = sphere_scene();
  FusionOptions o;
  o.voxel_size_m = 0;
  const int all = fuse_depth_maps(s.views, s.map_views, s.maps, o).size();
  o.voxel_size_m = 0.004;
  const OrientedPointCloud merged = fuse_depth_maps(s.views, s.map_views, s.maps, o);
  EXPECT_LT(merged.size(), all / 3);
  for (int i = 0; i < merged.size(); ++i) ASSERT_NEAR(merged.points.row(i).cast<double>().norm(), kRadius, 1e-3);
}

TEST(Fusion, PixelStepTakesEveryNthPixel) {
  const Scene s = sphere_scene();
  FusionOptions o;
  o.voxel_size_m = 0;
  const int all = fuse_depth_maps(s.views, s.map_views, s.maps, o).size();
  o.pixel_step = 2;
  const OrientedPointCloud sparse = fuse_depth_maps(s.views, s.map_views, s.maps, o);
  EXPECT_NEAR(double(sparse.size()) / all, 0.25, 0.03);
  for (int i = 0; i < sparse.size(); ++i) ASSERT_NEAR(sparse.points.row(i).cast<double>().norm(), kRadius, 2e-4);
  o.pixel_step = 0;
  EXPECT_THROW(fuse_depth_maps(s.views, s.map_views, s.maps, o), Error);
}

// The sphere's maps with noise, so that fusion's thresholds decide, and colours on every other view.
Scene noisy_coloured_sphere() {
  Scene s = sphere_scene();
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.0003f);
  for (DepthMap& map : s.maps)
    for (float& depth : map.depth)
      if (depth > 0) depth += noise(rng);
  for (size_t k = 0; k < s.views.size(); k += 2) {
    StereoView& view = s.views[k];
    view.colour = Image8(view.camera.width, view.camera.height, 3);
    for (int y = 0; y < view.camera.height; ++y)
      for (int x = 0; x < view.camera.width; ++x) {
        view.colour.at(x, y, 0) = uint8_t(2 * x);
        view.colour.at(x, y, 1) = uint8_t(3 * y);
        view.colour.at(x, y, 2) = uint8_t(40 * k);
      }
  }
  return s;
}

template <class Rows>
Eigen::Vector3d mean_row(const Rows& rows) {
  return rows.template cast<double>().colwise().mean().transpose();
}

TEST(FusionCuda, MatchesTheCpuPath) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const Scene s = noisy_coloured_sphere();
  for (const double voxel : {0.0, 0.004})
    for (const int step : {1, 2}) {
      SCOPED_TRACE("voxel " + std::to_string(voxel) + " m, pixel step " + std::to_string(step));
      FusionOptions o;
      o.voxel_size_m = voxel;
      o.pixel_step = step;
      const OrientedPointCloud cpu = fuse_depth_maps(s.views, s.map_views, s.maps, o, nullptr, Device::cpu);
      const OrientedPointCloud gpu = fuse_depth_maps(s.views, s.map_views, s.maps, o, nullptr, Device::cuda);
      ASSERT_GT(cpu.size(), 500);
      // The kernel rounds as the CPU does (mvs/CMakeLists.txt); a pixel on a threshold may still
      // tip where the two compilers order a sum differently.
      ASSERT_NEAR(gpu.size(), cpu.size(), 0.005 * cpu.size());
      EXPECT_LT((mean_row(gpu.points) - mean_row(cpu.points)).norm(), 2e-5);
      EXPECT_LT((mean_row(gpu.normals) - mean_row(cpu.normals)).norm(), 2e-3);
      EXPECT_LT((mean_row(gpu.colors) - mean_row(cpu.colors)).norm(), 1.0);
      if (gpu.size() != cpu.size()) continue;
      // The same points in the same order.
      EXPECT_LT((gpu.points - cpu.points).cwiseAbs().maxCoeff(), 1e-5);
      EXPECT_LT((gpu.normals - cpu.normals).cwiseAbs().maxCoeff(), 1e-4);
      EXPECT_LE((gpu.colors.cast<int>() - cpu.colors.cast<int>()).cwiseAbs().maxCoeff(), 1);
    }
}

}  // namespace
}  // namespace tega::mvs
