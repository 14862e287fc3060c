#include "colmap_tie_points.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <optional>

namespace tega::mvs {
namespace {

// About this many grid points along a view's longer side.
constexpr int kGridPointsAlongLongerSide = 32;
// COLMAP's fusion default (max_depth_error): relative depth difference of one surface.
constexpr double kMaxRelativeDepthDifference = 0.01;

// A camera and its depth map, whose pixels may be a scaled copy of the camera's.
struct View {
  int camera_index;
  const Camera* camera;
  const DepthMap* depth;
  double scale_x, scale_y;  // depth map pixels per camera pixel

  Eigen::Vector2d camera_pixel(double x, double y) const {
    return {(x + 0.5) / scale_x - 0.5, (y + 0.5) / scale_y - 0.5};
  }
  Eigen::Vector2d depth_pixel(const Eigen::Vector2d& p) const {
    return {(p.x() + 0.5) * scale_x - 0.5, (p.y() + 0.5) * scale_y - 0.5};
  }
  Eigen::Vector3d world_point(const Eigen::Vector2d& camera_pixel, double depth_m) const {
    const Eigen::Vector3d ray = camera->K.inverse() * camera_pixel.homogeneous();
    return camera->world_to_camera.R.transpose() * (ray * depth_m - camera->world_to_camera.t);
  }
  // The camera pixel where this view sees `world` consistently with its depth map.
  std::optional<Eigen::Vector2d> consistent_pixel(const Eigen::Vector3d& world) const {
    const Eigen::Vector3d in_camera = camera->world_to_camera.R * world + camera->world_to_camera.t;
    if (!(in_camera.z() > 0)) return std::nullopt;
    const Eigen::Vector2d pixel = (camera->K * in_camera).hnormalized();
    const Eigen::Vector2d d = depth_pixel(pixel);
    const long x = std::lround(d.x()), y = std::lround(d.y());
    if (x < 0 || y < 0 || x >= depth->width || y >= depth->height) return std::nullopt;
    const double seen = depth->depth[depth->index(int(x), int(y))];
    if (!(seen > 0) || std::abs(seen - in_camera.z()) > kMaxRelativeDepthDifference * in_camera.z())
      return std::nullopt;
    return pixel;
  }
};

}  // namespace

std::vector<ColmapPoint> tie_points_from_depth_maps(const Rig& rig, const std::map<std::string, DepthMap>& depth_maps) {
  std::vector<View> views;
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& camera = rig.cameras[i];
    const auto found = depth_maps.find(camera.name);
    if (found == depth_maps.end() || found->second.width == 0) continue;
    views.push_back({int(i), &camera, &found->second, double(found->second.width) / camera.width,
                     double(found->second.height) / camera.height});
  }
  std::vector<ColmapPoint> points;
  for (const View& reference : views) {
    const DepthMap& depth = *reference.depth;
    const int step = std::max(1, std::max(depth.width, depth.height) / kGridPointsAlongLongerSide);
    for (int y = step / 2; y < depth.height; y += step)
      for (int x = step / 2; x < depth.width; x += step) {
        const float d = depth.depth[depth.index(x, y)];
        if (!(d > 0)) continue;
        ColmapPoint point;
        const Eigen::Vector2d pixel = reference.camera_pixel(x, y);
        point.position = reference.world_point(pixel, d);
        point.observations.emplace_back(reference.camera_index, pixel);
        for (const View& other : views)
          if (&other != &reference)
            if (const auto seen = other.consistent_pixel(point.position))
              point.observations.emplace_back(other.camera_index, *seen);
        if (point.observations.size() >= 2) points.push_back(std::move(point));
      }
  }
  return points;
}

}  // namespace tega::mvs
