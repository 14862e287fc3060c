#pragma once
// Analytic scenes for the mvs tests: a sphere at the origin seen by cameras on
// a cap above it, with exact depth and normal maps, point clouds sampled on
// it, and sphere meshes.

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <string>

#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/mvs/depth_map.h"
#include "tega/mvs/point_cloud.h"

namespace tega::mvs::test {

// The radius of the tests' sphere, metres.
inline constexpr double kRadius = 0.1;

// A camera at `center` looking at the origin (OpenCV axes).
inline Camera camera_looking_at_origin(const std::string& name, const Eigen::Vector3d& center, int width, int height,
                                       double focal) {
  const Eigen::Vector3d z = -center.normalized();
  const Eigen::Vector3d hint = std::abs(z.y()) < 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = hint.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Camera camera;
  camera.name = name;
  camera.width = width;
  camera.height = height;
  camera.K << focal, 0, (width - 1) / 2.0, 0, focal, (height - 1) / 2.0, 0, 0, 1;
  camera.world_to_camera.R.row(0) = x.transpose();
  camera.world_to_camera.R.row(1) = y.transpose();
  camera.world_to_camera.R.row(2) = z.transpose();
  camera.world_to_camera.t = -camera.world_to_camera.R * center;
  return camera;
}

// One camera straight above the sphere (+z) and `ring` around it, `tilt_deg` off the axis.
inline Rig cap_rig(int ring, double tilt_deg, double distance, int width, int height, double focal) {
  Rig rig;
  rig.cameras.push_back(camera_looking_at_origin("cam00", {0, 0, distance}, width, height, focal));
  const double tilt = tilt_deg * std::numbers::pi / 180;
  for (int i = 0; i < ring; ++i) {
    const double azimuth = 2 * std::numbers::pi * i / ring;
    const Eigen::Vector3d direction(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                                    std::cos(tilt));
    rig.cameras.push_back(camera_looking_at_origin("cam" + std::string(i + 1 < 10 ? "0" : "") + std::to_string(i + 1),
                                                   distance * direction, width, height, focal));
  }
  return rig;
}

// Where the ray through `pixel` first meets the sphere (world), if it does.
inline std::optional<Eigen::Vector3d> sphere_hit(const Camera& camera, double x, double y, double radius) {
  const Eigen::Vector3d center = camera.center();
  const Eigen::Vector3d direction =
      (camera.world_to_camera.R.transpose() * (camera.K.inverse() * Eigen::Vector3d(x, y, 1))).normalized();
  const double b = center.dot(direction), c = center.squaredNorm() - radius * radius;
  const double discriminant = b * b - c;
  if (discriminant < 0) return std::nullopt;
  const double s = -b - std::sqrt(discriminant);
  if (s <= 0) return std::nullopt;
  return center + s * direction;
}

// Depth and normal of the ray through each pixel's centre moved by `pixel_offset`.
inline DepthMap sphere_depth_map(const Camera& camera, double radius, double pixel_offset = 0) {
  DepthMap map(camera.width, camera.height);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      if (const auto hit = sphere_hit(camera, x + pixel_offset, y + pixel_offset, radius)) {
        const size_t i = map.index(x, y);
        map.depth[i] = float(camera.world_to_camera.apply(*hit).z());
        const Eigen::Vector3d normal = camera.world_to_camera.R * (*hit / radius);
        for (int k = 0; k < 3; ++k) map.normals[3 * i + size_t(k)] = float(normal[k]);
        map.cost[i] = 0.1f;
      }
  return map;
}

// The sphere coloured by its normal, on a grey background.
inline Image8 sphere_image(const Camera& camera, double radius) {
  Image8 image(camera.width, camera.height, 3, 90);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      if (const auto hit = sphere_hit(camera, x, y, radius))
        for (int k = 0; k < 3; ++k) image.at(x, y, k) = uint8_t(std::lround(127.5 + 127 * (*hit)[k] / radius));
  return image;
}

// `count` points spread evenly over the sphere (a Fibonacci lattice), normals
// outward; only those with z >= min_z.
inline OrientedPointCloud sphere_cloud(int count, double radius, double min_z = -1e9) {
  std::vector<Eigen::Vector3f> directions;
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1 - 2 * (i + 0.5) / count, r = std::sqrt(1 - z * z);
    const Eigen::Vector3d d(r * std::cos(golden * i), r * std::sin(golden * i), z);
    if (radius * z >= min_z) directions.push_back(d.cast<float>());
  }
  OrientedPointCloud cloud;
  cloud.points.resize(Eigen::Index(directions.size()), 3);
  cloud.normals.resize(Eigen::Index(directions.size()), 3);
  for (size_t i = 0; i < directions.size(); ++i) {
    cloud.normals.row(Eigen::Index(i)) = directions[i].transpose();
    cloud.points.row(Eigen::Index(i)) = float(radius) * directions[i].transpose();
  }
  return cloud;
}

// An icosahedron subdivided `levels` times, vertices on the sphere, faces
// counter-clockwise seen from outside.
inline Mesh sphere_mesh(double radius, int levels) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> vertices = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                                           {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  std::vector<Eigen::Vector3i> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                        {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                        {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                        {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Eigen::Vector3d& v : vertices) v.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto [at, added] = midpoints.emplace(key, int(vertices.size()));
      if (added) vertices.push_back((vertices[size_t(a)] + vertices[size_t(b)]).normalized());
      return at->second;
    };
    std::vector<Eigen::Vector3i> finer;
    for (const Eigen::Vector3i& f : faces) {
      const int ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  Mesh mesh;
  mesh.positions.resize(Eigen::Index(vertices.size()), 3);
  for (size_t i = 0; i < vertices.size(); ++i)
    mesh.positions.row(Eigen::Index(i)) = (radius * vertices[i]).cast<float>().transpose();
  mesh.faces.resize(Eigen::Index(faces.size()), 3);
  for (size_t i = 0; i < faces.size(); ++i) mesh.faces.row(Eigen::Index(i)) = faces[i].transpose();
  return mesh;
}

}  // namespace tega::mvs::test
