#include "tega/mvs/fusion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "fusion_cuda.h"
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
detail::FusionView fusion_view(const StereoView& view, const DepthMap& map) {
  detail::FusionView v;
  v.depth = map.depth.data();
  v.normals = map.normals.data();
  v.colour = view.colour.empty() ? nullptr : view.colour.pixels.data();
  v.grey = view.grey.pixels.data();
  v.width = map.width;
  v.height = map.height;
  const Eigen::Matrix3f R = view.camera.world_to_camera.R.cast<float>();
  const Eigen::Matrix3f K = view.camera.K.cast<float>(), K_inverse = view.camera.K.inverse().cast<float>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      v.R[3 * i + j] = R(i, j);
      v.R_world[3 * i + j] = R(j, i);
      v.K[3 * i + j] = K(i, j);
      v.K_inverse[3 * i + j] = K_inverse(i, j);
    }
  const Eigen::Vector3f t = view.camera.world_to_camera.t.cast<float>(), centre = view.camera.center().cast<float>();
  for (int k = 0; k < 3; ++k) {
    v.t[k] = t(k);
    v.centre[k] = centre(k);
  }
  return v;
}

struct FusedPoint {
  Eigen::Vector3f point, normal, colour;
};

FusedPoint fused_point(const detail::FusedSample& s) {
  return {Eigen::Vector3f(s.point[0], s.point[1], s.point[2]), Eigen::Vector3f(s.normal[0], s.normal[1], s.normal[2]),
          Eigen::Vector3f(s.colour[0], s.colour[1], s.colour[2])};
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
                                   const std::vector<DepthMap>& maps, const FusionOptions& options, ThreadPool* pool,
                                   Device device) {
  if (map_views.size() != maps.size()) throw Error("fusion: one view index per depth map is needed");
  if (options.pixel_step < 1) throw Error("fusion: pixel_step must be at least 1");
  std::vector<detail::FusionView> inputs;
  for (size_t k = 0; k < maps.size(); ++k) {
    const StereoView& view = views.at(map_views[k]);
    if (maps[k].width != view.camera.width || maps[k].height != view.camera.height)
      throw Error("fusion: the depth map of " + view.camera.name + " does not have the camera's size");
    if (view.camera.has_distortion()) throw Error("fusion: the camera of " + view.camera.name + " must be undistorted");
    const size_t pixels = size_t(view.camera.width) * view.camera.height;
    if (view.colour.empty() ? view.grey.pixels.size() != pixels : view.colour.pixels.size() != 3 * pixels)
      throw Error("fusion: the view of " + view.camera.name + " has neither an RGB nor a grey image of its size");
    inputs.push_back(fusion_view(view, maps[k]));
  }
  std::optional<ThreadPool> own_pool;
  if (!pool) pool = &own_pool.emplace(0);
  detail::FusionParameters parameters;
  parameters.min_consistent_views = options.min_consistent_views;
  parameters.max_depth_error = options.max_depth_error;
  parameters.max_reprojection_px = options.max_reprojection_px;
  parameters.cos_max_angle = std::cos(options.max_normal_angle_deg * float(M_PI) / 180.0f);

  const auto start = std::chrono::steady_clock::now();
  std::vector<FusedPoint> points;
  if (device == Device::cuda) {
    for (const detail::FusedSample& s : detail::fuse_pixels_cuda(inputs, parameters, options.pixel_step))
      points.push_back(fused_point(s));
  } else {
    // Rows in parallel, collected in row order: the same cloud for any thread count.
    std::vector<std::vector<FusedPoint>> rows;
    for (size_t r = 0; r < inputs.size(); ++r) {
      const int width = inputs[r].width, height = inputs[r].height, step = options.pixel_step;
      rows.assign(size_t((height + step - 1) / step), {});
      pool->parallel_for(0, int64_t(rows.size()), [&](int64_t row) {
        const int y = int(row) * step;
        detail::FusedSample sample;
        for (int x = 0; x < width; x += step)
          if (detail::fuse_pixel(inputs.data(), int(inputs.size()), int(r), x, y, parameters, sample))
            rows[size_t(row)].push_back(fused_point(sample));
      });
      for (const auto& row : rows) points.insert(points.end(), row.begin(), row.end());
    }
  }
  const double pixels_s = seconds_since(start);
  OrientedPointCloud cloud =
      to_cloud(options.voxel_size_m > 0 ? merge_voxels(points, options.voxel_size_m, *pool) : points);
  logging::debug("fusion: %zu points from the pixels in %.2f s, %d after merging in %.2f s", points.size(), pixels_s,
                 cloud.size(), seconds_since(start) - pixels_s);
  return cloud;
}

}  // namespace tega::mvs
