#include "tega/mvs/fusion.h"

#include <cmath>
#include <optional>
#include <unordered_map>

#include "tega/core/error.h"
#include "tega/core/thread_pool.h"

namespace tega::mvs {
namespace {

struct MapView {
  const Camera* camera;
  const DepthMap* map;
  const StereoView* view;
  Eigen::Matrix3f R_world;  // camera -> world rotation
  Eigen::Matrix3f K_inverse;
};

struct FusedPoint {
  Eigen::Vector3f point, normal, colour;
};

Eigen::Vector3f colour_at(const StereoView& view, int x, int y) {
  if (!view.colour.empty())
    return {float(view.colour.at(x, y, 0)), float(view.colour.at(x, y, 1)), float(view.colour.at(x, y, 2))};
  const float g = 255.0f * view.grey.at(x, y, 0);
  return {g, g, g};
}

Eigen::Vector3f world_point(const MapView& m, int x, int y, float depth) {
  const Eigen::Vector3f camera_point = depth * (m.K_inverse * Eigen::Vector3f(float(x), float(y), 1.0f));
  return m.camera->world_to_camera.inverse().apply(camera_point.cast<double>()).cast<float>();
}

Eigen::Vector3f world_normal(const MapView& m, size_t i) {
  return m.R_world * Eigen::Vector3f(m.map->normals[3 * i], m.map->normals[3 * i + 1], m.map->normals[3 * i + 2]);
}

std::optional<FusedPoint> fuse_pixel(const std::vector<MapView>& maps, size_t r, int x, int y,
                                     const FusionOptions& o, float cos_max_angle) {
  const MapView& ref = maps[r];
  const size_t i = ref.map->index(x, y);
  const float depth = ref.map->depth[i];
  if (depth <= 0) return std::nullopt;
  const Eigen::Vector3f X = world_point(ref, x, y, depth);
  const Eigen::Vector3f n = world_normal(ref, i);
  FusedPoint sum{X, n, colour_at(*ref.view, x, y)};
  int confirmations = 0;
  for (size_t v = 0; v < maps.size(); ++v) {
    if (v == r) continue;
    const MapView& other = maps[v];
    const auto pixel = other.camera->project(X.cast<double>());
    if (!pixel) continue;
    const int ox = int(std::lround(pixel->x())), oy = int(std::lround(pixel->y()));
    if (ox < 0 || oy < 0 || ox >= other.map->width || oy >= other.map->height) continue;
    const size_t j = other.map->index(ox, oy);
    const float other_depth = other.map->depth[j];
    if (other_depth <= 0) continue;
    const float projected_depth = float(other.camera->world_to_camera.apply(X.cast<double>()).z());
    if (std::abs(projected_depth - other_depth) > o.max_depth_error * other_depth) continue;
    const Eigen::Vector3f Y = world_point(other, ox, oy, other_depth);
    const auto back = ref.camera->project(Y.cast<double>());
    if (!back || (*back - Eigen::Vector2d(x, y)).norm() > o.max_reprojection_px) continue;
    const Eigen::Vector3f m = world_normal(other, j);
    if (m.dot(n) < cos_max_angle) continue;
    sum.point += Y;
    sum.normal += m;
    sum.colour += colour_at(*other.view, ox, oy);
    ++confirmations;
  }
  if (confirmations < o.min_consistent_views) return std::nullopt;
  const float count = float(confirmations + 1);
  return FusedPoint{sum.point / count, sum.normal.normalized(), sum.colour / count};
}

struct VoxelSum {
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero(), colour = Eigen::Vector3d::Zero();
  int count = 0;
};

OrientedPointCloud to_cloud(const std::vector<FusedPoint>& points) {
  OrientedPointCloud cloud;
  cloud.points.resize(Eigen::Index(points.size()), 3);
  cloud.normals.resize(Eigen::Index(points.size()), 3);
  cloud.colors.resize(Eigen::Index(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k) {
    cloud.points.row(Eigen::Index(k)) = points[k].point;
    cloud.normals.row(Eigen::Index(k)) = points[k].normal;
    cloud.colors.row(Eigen::Index(k)) = points[k].colour.array().round().min(255.0f).max(0.0f).cast<uint8_t>();
  }
  return cloud;
}

std::vector<FusedPoint> merge_voxels(const std::vector<FusedPoint>& points, double voxel) {
  std::unordered_map<uint64_t, VoxelSum> voxels;
  voxels.reserve(points.size() / 4);
  const auto cell = [voxel](float v) { return uint64_t(int64_t(std::floor(v / voxel)) & 0x1fffff); };
  std::vector<uint64_t> order;  // first appearance, so the output does not depend on hashing
  for (const auto& p : points) {
    const uint64_t key = (cell(p.point.x()) << 42) | (cell(p.point.y()) << 21) | cell(p.point.z());
    VoxelSum& sum = voxels[key];
    if (sum.count == 0) order.push_back(key);
    sum.point += p.point.cast<double>();
    sum.normal += p.normal.cast<double>();
    sum.colour += p.colour.cast<double>();
    ++sum.count;
  }
  std::vector<FusedPoint> merged;
  merged.reserve(order.size());
  for (uint64_t key : order) {
    const VoxelSum& s = voxels.at(key);
    if (s.normal.squaredNorm() == 0) continue;  // opposite normals cancelled: no orientation to keep
    merged.push_back({(s.point / s.count).cast<float>(), s.normal.normalized().cast<float>(),
                      (s.colour / s.count).cast<float>()});
  }
  return merged;
}

}  // namespace

OrientedPointCloud fuse_depth_maps(const std::vector<StereoView>& views, const std::vector<int>& map_views,
                                   const std::vector<DepthMap>& maps, const FusionOptions& options, ThreadPool* pool) {
  if (map_views.size() != maps.size()) throw Error("fusion: one view index per depth map is needed");
  if (options.pixel_step < 1) throw Error("fusion: pixel_step must be at least 1");
  std::vector<MapView> inputs;
  for (size_t k = 0; k < maps.size(); ++k) {
    const StereoView& view = views.at(map_views[k]);
    if (maps[k].width != view.camera.width || maps[k].height != view.camera.height)
      throw Error("fusion: the depth map of " + view.camera.name + " does not have the camera's size");
    inputs.push_back({&view.camera, &maps[k], &view, view.camera.world_to_camera.R.transpose().cast<float>(),
                      view.camera.K.inverse().cast<float>()});
  }
  std::optional<ThreadPool> own_pool;
  if (!pool) pool = &own_pool.emplace(0);
  const float cos_max_angle = std::cos(options.max_normal_angle_deg * float(M_PI) / 180.0f);

  // Rows in parallel, collected in row order: the same cloud for any thread count.
  std::vector<std::vector<FusedPoint>> rows;
  std::vector<FusedPoint> points;
  for (size_t r = 0; r < inputs.size(); ++r) {
    const int width = inputs[r].map->width, height = inputs[r].map->height, step = options.pixel_step;
    rows.assign(size_t((height + step - 1) / step), {});
    pool->parallel_for(0, int64_t(rows.size()), [&](int64_t row) {
      const int y = int(row) * step;
      for (int x = 0; x < width; x += step)
        if (auto p = fuse_pixel(inputs, r, x, y, options, cos_max_angle)) rows[size_t(row)].push_back(*p);
    });
    for (const auto& row : rows) points.insert(points.end(), row.begin(), row.end());
  }
  return to_cloud(options.voxel_size_m > 0 ? merge_voxels(points, options.voxel_size_m) : points);
}

}  // namespace tega::mvs
