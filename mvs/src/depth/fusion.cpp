#include "tega/mvs/fusion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/thread_pool.h"

namespace tega::mvs {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A view's pinhole camera in float: fusion projects every pixel into every
// other view, and Camera::project's double precision and lens model cost
// several times more than the arithmetic needs (the views are undistorted).
struct MapView {
  const DepthMap* map;
  const StereoView* view;
  Eigen::Matrix3f R, R_world;  // world -> camera, camera -> world
  Eigen::Vector3f t, centre;   // world -> camera translation; the camera centre in the world
  Eigen::Matrix3f K, K_inverse;

  Eigen::Vector3f to_camera(const Eigen::Vector3f& world) const { return R * world + t; }
  // The pixel of a point in front of the camera (in camera coordinates).
  Eigen::Vector2f pixel(const Eigen::Vector3f& camera) const {
    const Eigen::Vector3f p = K * camera;
    return {p.x() / p.z(), p.y() / p.z()};
  }
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
  return m.R_world * (depth * (m.K_inverse * Eigen::Vector3f(float(x), float(y), 1.0f))) + m.centre;
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
    const Eigen::Vector3f in_other = other.to_camera(X);
    if (in_other.z() <= 0) continue;
    const Eigen::Vector2f pixel = other.pixel(in_other);
    const int ox = int(std::lround(pixel.x())), oy = int(std::lround(pixel.y()));
    if (ox < 0 || oy < 0 || ox >= other.map->width || oy >= other.map->height) continue;
    const size_t j = other.map->index(ox, oy);
    const float other_depth = other.map->depth[j];
    if (other_depth <= 0) continue;
    if (std::abs(in_other.z() - other_depth) > o.max_depth_error * other_depth) continue;
    const Eigen::Vector3f Y = world_point(other, ox, oy, other_depth);
    const Eigen::Vector3f back = ref.to_camera(Y);
    if (back.z() <= 0 || (ref.pixel(back) - Eigen::Vector2f(float(x), float(y))).norm() > o.max_reprojection_px)
      continue;
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

// Voxels fall into a fixed number of groups by key, merged in parallel; each
// voxel sums its points in input order and the voxels come out in the order of
// their first point, so the cloud depends neither on hashing nor on threads.
std::vector<FusedPoint> merge_voxels(const std::vector<FusedPoint>& points, double voxel, ThreadPool& pool) {
  constexpr uint64_t kGroups = 64;
  const auto cell = [voxel](float v) { return uint64_t(int64_t(std::floor(v / voxel)) & 0x1fffff); };
  std::vector<uint64_t> keys(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i].point;
    keys[i] = (cell(p.x()) << 42) | (cell(p.y()) << 21) | cell(p.z());
  }
  const auto group_of = [](uint64_t key) { return (key * 0x9e3779b97f4a7c15ull) >> 58; };  // top 6 bits: 64 groups
  std::vector<std::vector<uint32_t>> groups(kGroups);
  for (size_t i = 0; i < points.size(); ++i) groups[group_of(keys[i])].push_back(uint32_t(i));

  std::vector<std::vector<std::pair<uint32_t, FusedPoint>>> merged_groups(kGroups);  // (first point, voxel)
  // 64 tasks: the pool's shared counter costs nothing here.
  pool.parallel_for(0, int64_t(kGroups), [&](int64_t g) {
    std::unordered_map<uint64_t, VoxelSum> voxels;
    std::vector<std::pair<uint64_t, uint32_t>> order;  // key, first point
    voxels.reserve(groups[size_t(g)].size() / 4);
    for (uint32_t i : groups[size_t(g)]) {
      const FusedPoint& p = points[i];
      VoxelSum& sum = voxels[keys[i]];
      if (sum.count == 0) order.emplace_back(keys[i], i);
      sum.point += p.point.cast<double>();
      sum.normal += p.normal.cast<double>();
      sum.colour += p.colour.cast<double>();
      ++sum.count;
    }
    auto& out = merged_groups[size_t(g)];
    for (const auto& [key, first] : order) {
      const VoxelSum& s = voxels.at(key);
      if (s.normal.squaredNorm() == 0) continue;  // opposite normals cancelled: no orientation to keep
      out.push_back({first, {(s.point / s.count).cast<float>(), s.normal.normalized().cast<float>(),
                             (s.colour / s.count).cast<float>()}});
    }
  });
  std::vector<std::pair<uint32_t, FusedPoint>> all;
  for (auto& group : merged_groups) all.insert(all.end(), group.begin(), group.end());
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<FusedPoint> merged;
  merged.reserve(all.size());
  for (const auto& entry : all) merged.push_back(entry.second);
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
    if (view.camera.has_distortion()) throw Error("fusion: the camera of " + view.camera.name + " must be undistorted");
    MapView m;
    m.map = &maps[k];
    m.view = &view;
    m.R = view.camera.world_to_camera.R.cast<float>();
    m.R_world = m.R.transpose();
    m.t = view.camera.world_to_camera.t.cast<float>();
    m.centre = view.camera.center().cast<float>();
    m.K = view.camera.K.cast<float>();
    m.K_inverse = view.camera.K.inverse().cast<float>();
    inputs.push_back(m);
  }
  std::optional<ThreadPool> own_pool;
  if (!pool) pool = &own_pool.emplace(0);
  const float cos_max_angle = std::cos(options.max_normal_angle_deg * float(M_PI) / 180.0f);

  const auto start = std::chrono::steady_clock::now();
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
  const double pixels_s = seconds_since(start);
  OrientedPointCloud cloud =
      to_cloud(options.voxel_size_m > 0 ? merge_voxels(points, options.voxel_size_m, *pool) : points);
  logging::debug("fusion: %zu points from the pixels in %.2f s, %d after merging in %.2f s", points.size(), pixels_s,
                 cloud.size(), seconds_since(start) - pixels_s);
  return cloud;
}

}  // namespace tega::mvs
