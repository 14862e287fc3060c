#include "pyramid.h"

#include <algorithm>
#include <cmath>

namespace tega::mvs::detail {

StereoView half_size(const StereoView& view) {
  StereoView half;
  half.camera = view.camera.scaled(0.5);
  const int width = half.camera.width, height = half.camera.height;
  const int fine_width = view.camera.width, fine_height = view.camera.height;
  half.grey = ImageF(width, height, 1);
  if (!view.mask.empty()) half.mask.assign(size_t(width) * height, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float sum = 0;
      bool inside = false;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const size_t i = size_t(std::min(2 * y + dy, fine_height - 1)) * fine_width + std::min(2 * x + dx, fine_width - 1);
          sum += view.grey.pixels[i];
          inside = inside || (!view.mask.empty() && view.mask[i]);
        }
      half.grey.pixels[size_t(y) * width + x] = 0.25f * sum;
      if (inside) half.mask[size_t(y) * width + x] = 255;
    }
  return half;
}

DepthMap upsampled(const DepthMap& coarse, const Camera& coarse_camera, const StereoView& fine, const Parameters& p) {
  const int width = fine.camera.width, height = fine.camera.height;
  DepthMap map(width, height);
  float coarse_K_inverse[9], fine_K_inverse[9];
  const Eigen::Matrix3d ci = coarse_camera.K.inverse(), fi = fine.camera.K.inverse();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      coarse_K_inverse[3 * r + c] = float(ci(r, c));
      fine_K_inverse[3 * r + c] = float(fi(r, c));
    }
  const float scale_x = float(coarse.width) / float(width), scale_y = float(coarse.height) / float(height);
  for (int y = 0; y < height; ++y) {
    const int cy = std::clamp(int(std::lround(scale_y * (y + 0.5f) - 0.5f)), 0, coarse.height - 1);
    for (int x = 0; x < width; ++x) {
      const size_t i = map.index(x, y);
      if (!fine.mask.empty() && !fine.mask[i]) continue;
      const int cx = std::clamp(int(std::lround(scale_x * (x + 0.5f) - 0.5f)), 0, coarse.width - 1);
      const size_t j = coarse.index(cx, cy);
      float ray[3];
      pixel_ray(fine_K_inverse, float(x), float(y), ray);
      float depth = 0, normal[3] = {0, 0, 0};
      if (coarse.depth[j] > 0) {
        float coarse_ray[3];
        pixel_ray(coarse_K_inverse, float(cx), float(cy), coarse_ray);
        const float point[3] = {coarse.depth[j] * coarse_ray[0], coarse.depth[j] * coarse_ray[1],
                                coarse.depth[j] * coarse_ray[2]};
        for (int k = 0; k < 3; ++k) normal[k] = coarse.normals[3 * j + k];
        depth = plane_depth(point, normal, ray);
      }
      if (depth >= p.depth_min && depth <= p.depth_max && faces_camera(normal, ray)) {
        map.cost[i] = coarse.cost[j];
      } else {
        depth = random_depth(p, random_uniform(p.seed, x, y, 0, 0));
        random_normal(ray, random_uniform(p.seed, x, y, 0, 1), random_uniform(p.seed, x, y, 0, 2), normal);
        if (!faces_camera(normal, ray)) {  // head-on, when the draw grazes
          for (int k = 0; k < 3; ++k) normal[k] = -ray[k];
          normalize3(normal);
        }
        map.cost[i] = kMaxCost;
      }
      map.depth[i] = depth;
      for (int k = 0; k < 3; ++k) map.normals[3 * i + k] = normal[k];
    }
  }
  return map;
}

}  // namespace tega::mvs::detail
