#pragma once
// The per-pixel math of depth-map fusion, shared by the CPU path and the CUDA
// kernel (plain C++17 on raw pointers; TEGA_HD makes it __host__ __device__).
//
// A pixel of a reference view with a depth is a world point X. Another view
// confirms it where X projects inside it onto a pixel whose own depth agrees
// (relative error at most max_depth_error), whose point projects back within
// max_reprojection_px of the pixel, and whose normal lies within the angle.
// The pixel becomes a point when min_consistent_views confirm it: the mean of
// its point and the confirming points, their normals' mean direction and their
// colours' mean. Cameras are undistorted pinholes, in float.

#include <cmath>
#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::mvs::detail {

struct FusionView {
  const float* depth = nullptr;    // width * height, 0 = no estimate
  const float* normals = nullptr;  // 3 per pixel, camera frame
  const uint8_t* colour = nullptr; // RGB per pixel; nullptr: `grey` gives the colour
  const float* grey = nullptr;     // [0, 1]
  int width = 0, height = 0;
  float R[9], R_world[9];  // world -> camera, camera -> world (row-major)
  float t[3], centre[3];   // world -> camera translation; the camera centre in the world
  float K[9], K_inverse[9];
};

struct FusionParameters {
  int min_consistent_views = 2;
  float max_depth_error = 0, max_reprojection_px = 0, cos_max_angle = 0;
};

struct FusedSample {
  float point[3], normal[3], colour[3];
};

TEGA_HD void multiply(const float* M, const float* v, float* out) {
  out[0] = M[0] * v[0] + M[1] * v[1] + M[2] * v[2];
  out[1] = M[3] * v[0] + M[4] * v[1] + M[5] * v[2];
  out[2] = M[6] * v[0] + M[7] * v[1] + M[8] * v[2];
}

TEGA_HD void to_camera(const FusionView& v, const float* world, float* camera) {
  multiply(v.R, world, camera);
  for (int k = 0; k < 3; ++k) camera[k] += v.t[k];
}

// The pixel of a point in front of the camera (camera coordinates).
TEGA_HD void pixel_of(const FusionView& v, const float* camera, float& px, float& py) {
  float p[3];
  multiply(v.K, camera, p);
  px = p[0] / p[2];
  py = p[1] / p[2];
}

TEGA_HD void world_point(const FusionView& v, int x, int y, float depth, float* world) {
  const float pixel[3] = {float(x), float(y), 1.0f};
  float ray[3], scaled[3];
  multiply(v.K_inverse, pixel, ray);
  for (int k = 0; k < 3; ++k) scaled[k] = depth * ray[k];
  multiply(v.R_world, scaled, world);
  for (int k = 0; k < 3; ++k) world[k] += v.centre[k];
}

TEGA_HD void world_normal(const FusionView& v, long long i, float* world) { multiply(v.R_world, v.normals + 3 * i, world); }

TEGA_HD void add_colour(const FusionView& v, long long i, float* sum) {
  if (v.colour) {
    for (int k = 0; k < 3; ++k) sum[k] += float(v.colour[3 * i + k]);
  } else {
    const float g = 255.0f * v.grey[i];
    for (int k = 0; k < 3; ++k) sum[k] += g;
  }
}

// Pixel (x, y) of views[r]; false where it makes no point.
TEGA_HD bool fuse_pixel(const FusionView* views, int view_count, int r, int x, int y, const FusionParameters& p,
                        FusedSample& out) {
  const FusionView& ref = views[r];
  const long long i = (long long)y * ref.width + x;
  const float depth = ref.depth[i];
  if (depth <= 0) return false;
  float X[3], n[3];
  world_point(ref, x, y, depth, X);
  world_normal(ref, i, n);
  float point[3] = {X[0], X[1], X[2]}, normal[3] = {n[0], n[1], n[2]}, colour[3] = {0, 0, 0};
  add_colour(ref, i, colour);
  int confirmations = 0;
  for (int v = 0; v < view_count; ++v) {
    if (v == r) continue;
    const FusionView& other = views[v];
    float in_other[3];
    to_camera(other, X, in_other);
    if (in_other[2] <= 0) continue;
    float px, py;
    pixel_of(other, in_other, px, py);
    const long ox = lroundf(px), oy = lroundf(py);
    if (ox < 0 || oy < 0 || ox >= other.width || oy >= other.height) continue;
    const long long j = (long long)oy * other.width + ox;
    const float other_depth = other.depth[j];
    if (other_depth <= 0) continue;
    if (fabsf(in_other[2] - other_depth) > p.max_depth_error * other_depth) continue;
    float Y[3], back[3];
    world_point(other, int(ox), int(oy), other_depth, Y);
    to_camera(ref, Y, back);
    if (back[2] <= 0) continue;
    float bx, by;
    pixel_of(ref, back, bx, by);
    const float dx = bx - float(x), dy = by - float(y);
    if (sqrtf(dx * dx + dy * dy) > p.max_reprojection_px) continue;
    float m[3];
    world_normal(other, j, m);
    if (m[0] * n[0] + m[1] * n[1] + m[2] * n[2] < p.cos_max_angle) continue;
    for (int k = 0; k < 3; ++k) {
      point[k] += Y[k];
      normal[k] += m[k];
    }
    add_colour(other, j, colour);
    ++confirmations;
  }
  if (confirmations < p.min_consistent_views) return false;
  const float count = float(confirmations + 1);
  const float length = sqrtf(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  for (int k = 0; k < 3; ++k) {
    out.point[k] = point[k] / count;
    out.normal[k] = length > 0 ? normal[k] / length : 0.0f;
    out.colour[k] = colour[k] / count;
  }
  return true;
}

}  // namespace tega::mvs::detail
