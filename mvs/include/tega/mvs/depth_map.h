#pragma once
// A view's depth and normal estimate, as PatchMatch stereo produces it and as
// COLMAP's dense workspace stores it (stereo/depth_maps, stereo/normal_maps).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tega::mvs {

struct DepthMap {
  int width = 0, height = 0;
  std::vector<float> depth;    // metres along the camera's z axis, row-major; 0 = no estimate
  std::vector<float> normals;  // 3 per pixel (x, y, z interleaved), camera frame, unit length,
                               // facing the camera; 0 where depth is 0
  std::vector<float> cost;     // matching cost in [0, 2] (1 - NCC, aggregated over source views)

  DepthMap() = default;
  DepthMap(int w, int h)
      : width(w), height(h), depth(size_t(w) * h, 0.0f), normals(size_t(w) * h * 3, 0.0f), cost(size_t(w) * h, 2.0f) {}
  size_t index(int x, int y) const { return size_t(y) * width + x; }
  int64_t valid_pixels() const;
};

}  // namespace tega::mvs
