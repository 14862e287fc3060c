#pragma once
// The per-pixel math of PatchMatch stereo, shared by the CPU path and the CUDA
// kernels (plain C++17 on raw pointers; TEGA_HD makes it __host__ __device__).
//
// A hypothesis is a plane in the reference camera's frame: the pixel's depth d
// along z and a unit normal n facing the camera. Its point is X = d K^-1 p and
// the plane n.Y = n.X. A source camera (Y_s = R Y + t) sees the plane through
// the homography H = K_s (R + t n^T / (n.X)) K^-1, which maps the reference
// window onto the source image; the window's bilateral-weighted NCC against
// the source is the photometric score.

#include <cmath>
#include <cstdint>

#include "tega/core/host_device.h"

namespace tega::mvs::detail {

constexpr int kMaxWindowSamples = 49;  // a 7 x 7 grid of samples
constexpr int kMaxSources = 16;
constexpr float kMaxCost = 2.0f;  // 1 - NCC lies in [0, 2]
constexpr int kPropagationCandidates = 4;  // of the eight neighbours

struct GreyImage {
  const float* pixels = nullptr;
  int width = 0, height = 0;
};

struct SourceView {
  GreyImage image;
  float K[9];             // intrinsics, row-major
  float R[9], t[3];       // reference camera frame -> source camera frame
  // Geometric pass: the source's depth map (nullptr: none) and what maps its pixels back.
  const float* depth = nullptr;
  float K_inverse[9];
  float R_back[9], t_back[3];  // source camera frame -> reference camera frame
};

struct ReferenceView {
  GreyImage image;
  const uint8_t* mask = nullptr;  // nullptr: every pixel
  float K[9], K_inverse[9];
};

struct Parameters {
  int window_half_samples = 2;  // samples on each side of the centre: (2h + 1)^2 samples
  int window_step = 2;
  float sigma_spatial = 4, sigma_color = 0.08f;
  float depth_min = 0, depth_max = 0;
  int num_sources = 0, top_k = 3;
  bool geometric = false;
  float geometric_weight = 0.2f, geometric_max_error = 3;
  uint32_t seed = 1;
  int iteration = 0, num_iterations = 1;  // perturbations shrink over the iterations
};

// The estimate of every pixel of a reference view.
struct PixelStates {
  float* depth;   // 0 = none (masked out)
  float* normal;  // 3 per pixel
  float* cost;
};

// ---- small vector helpers -------------------------------------------------

TEGA_HD void mat3_vec(const float* M, const float* v, float* out) {
  out[0] = M[0] * v[0] + M[1] * v[1] + M[2] * v[2];
  out[1] = M[3] * v[0] + M[4] * v[1] + M[5] * v[2];
  out[2] = M[6] * v[0] + M[7] * v[1] + M[8] * v[2];
}

TEGA_HD float dot3(const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

TEGA_HD void normalize3(float* v) {
  const float inv = 1.0f / sqrtf(dot3(v, v));
  v[0] *= inv;
  v[1] *= inv;
  v[2] *= inv;
}

// The ray of pixel (x, y) scaled to z = 1: depth d gives the point d * ray.
TEGA_HD void pixel_ray(const float* K_inverse, float x, float y, float* ray) {
  const float p[3] = {x, y, 1.0f};
  mat3_vec(K_inverse, p, ray);
}

// ---- random numbers: a pure function of (seed, pixel, iteration, stream) --

TEGA_HD uint32_t mix_bits(uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

TEGA_HD float random_uniform(uint32_t seed, int x, int y, int iteration, int stream) {
  uint32_t h = mix_bits(seed ^ 0x9e3779b9u);
  h = mix_bits(h ^ static_cast<uint32_t>(x));
  h = mix_bits(h ^ static_cast<uint32_t>(y) * 0x85ebca6bu);
  h = mix_bits(h ^ static_cast<uint32_t>(iteration * 64 + stream));
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

// ---- hypotheses -----------------------------------------------------------

// A normal is usable when it faces the camera at less than ~80 degrees from
// the viewing ray: beyond that the homography degenerates.
TEGA_HD bool faces_camera(const float* normal, const float* ray) {
  const float along = dot3(normal, ray);
  return along < -0.17f * sqrtf(dot3(ray, ray));
}

// Uniform in inverse depth, as disparity is.
TEGA_HD float random_depth(const Parameters& p, float u) {
  const float inverse = 1.0f / p.depth_max + u * (1.0f / p.depth_min - 1.0f / p.depth_max);
  return 1.0f / inverse;
}

// A random unit normal facing the camera along `ray`.
TEGA_HD void random_normal(const float* ray, float u1, float u2, float* normal) {
  const float z = 2.0f * u1 - 1.0f;
  const float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
  const float phi = 6.2831853f * u2;
  normal[0] = r * cosf(phi);
  normal[1] = r * sinf(phi);
  normal[2] = z;
  if (dot3(normal, ray) > 0) {
    normal[0] = -normal[0];
    normal[1] = -normal[1];
    normal[2] = -normal[2];
  }
}

// Depth at pixel ray `ray` of the plane through point `point` with `normal`
// (0 when the ray is parallel to it or meets it behind the camera).
TEGA_HD float plane_depth(const float* point, const float* normal, const float* ray) {
  const float denominator = dot3(normal, ray);
  if (fabsf(denominator) < 1e-9f) return 0.0f;
  const float depth = dot3(normal, point) / denominator;
  return depth > 0 ? depth : 0.0f;
}

// ---- the window of the reference pixel --------------------------------------

TEGA_HD float pixel_at(const GreyImage& image, int x, int y) {
  x = x < 0 ? 0 : (x >= image.width ? image.width - 1 : x);
  y = y < 0 ? 0 : (y >= image.height ? image.height - 1 : y);
  return image.pixels[y * image.width + x];
}

// Bilinear sample; negative when (x, y) lies outside the image.
TEGA_HD float bilinear(const GreyImage& image, float x, float y) {
  if (!(x >= 0.0f && y >= 0.0f && x <= image.width - 1.0f && y <= image.height - 1.0f)) return -1.0f;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = x0 + 1 < image.width ? x0 + 1 : x0, y1 = y0 + 1 < image.height ? y0 + 1 : y0;
  const float fx = x - x0, fy = y - y0;
  const float* row0 = image.pixels + y0 * image.width;
  const float* row1 = image.pixels + y1 * image.width;
  const float top = row0[x0] + fx * (row0[x1] - row0[x0]);
  const float bottom = row1[x0] + fx * (row1[x1] - row1[x0]);
  return top + fy * (bottom - top);
}

// The reference window's samples, bilateral weights and weighted statistics:
// they do not depend on the hypothesis, so each pixel update computes them once.
struct ReferenceWindow {
  float value[kMaxWindowSamples];
  float weight[kMaxWindowSamples];
  float weight_sum, mean, variance;  // weighted
  int count;
};

TEGA_HD void reference_window(const ReferenceView& ref, const Parameters& p, int x, int y, ReferenceWindow& w) {
  const float centre = pixel_at(ref.image, x, y);
  const float spatial = -0.5f / (p.sigma_spatial * p.sigma_spatial);
  const float colour = -0.5f / (p.sigma_color * p.sigma_color);
  const int h = p.window_half_samples;
  float sum_w = 0, sum_wv = 0, sum_wvv = 0;
  int n = 0;
  for (int j = -h; j <= h; ++j) {
    for (int i = -h; i <= h; ++i) {
      const int dx = i * p.window_step, dy = j * p.window_step;
      const float v = pixel_at(ref.image, x + dx, y + dy);
      const float dv = v - centre;
      const float weight = expf(spatial * static_cast<float>(dx * dx + dy * dy) + colour * dv * dv);
      w.value[n] = v;
      w.weight[n] = weight;
      sum_w += weight;
      sum_wv += weight * v;
      sum_wvv += weight * v * v;
      ++n;
    }
  }
  w.count = n;
  w.weight_sum = sum_w;
  w.mean = sum_wv / sum_w;
  w.variance = fmaxf(sum_wvv / sum_w - w.mean * w.mean, 0.0f);
}

// ---- costs ----------------------------------------------------------------

// H = K_s (R + t n^T / c) K^-1 with c = n.X.
TEGA_HD void plane_homography(const SourceView& s, const float* K_inverse, const float* normal, float plane_offset,
                              float* H) {
  float A[9];
  const float inv_c = 1.0f / plane_offset;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) A[r * 3 + c] = s.R[r * 3 + c] + s.t[r] * normal[c] * inv_c;
  float B[9];  // A K^-1
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      B[r * 3 + c] = A[r * 3 + 0] * K_inverse[0 * 3 + c] + A[r * 3 + 1] * K_inverse[1 * 3 + c] +
                     A[r * 3 + 2] * K_inverse[2 * 3 + c];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      H[r * 3 + c] = s.K[r * 3 + 0] * B[0 * 3 + c] + s.K[r * 3 + 1] * B[1 * 3 + c] + s.K[r * 3 + 2] * B[2 * 3 + c];
}

// 1 - weighted NCC of the reference window against the source image through H.
// The window's samples step along two axes, so their homogeneous source
// coordinates do too: one multiply-add per coordinate and one reciprocal per sample.
TEGA_HD float photometric_cost(const SourceView& s, const ReferenceWindow& w, const Parameters& p, int x, int y,
                               const float* H) {
  if (w.variance < 1e-8f) return kMaxCost;  // a flat window matches anything
  const int h = p.window_half_samples;
  const float step = static_cast<float>(p.window_step);
  const float x0 = static_cast<float>(x - h * p.window_step), y0 = static_cast<float>(y - h * p.window_step);
  const float di[3] = {H[0] * step, H[3] * step, H[6] * step};
  const float dj[3] = {H[1] * step, H[4] * step, H[7] * step};
  float row[3] = {H[0] * x0 + H[1] * y0 + H[2], H[3] * x0 + H[4] * y0 + H[5], H[6] * x0 + H[7] * y0 + H[8]};
  float sum_s = 0, sum_ss = 0, sum_rs = 0;
  int n = 0;
  for (int j = -h; j <= h; ++j) {
    float q[3] = {row[0], row[1], row[2]};
    for (int i = -h; i <= h; ++i) {
      if (q[2] <= 0.0f) return kMaxCost;
      const float inv_z = 1.0f / q[2];
      const float v = bilinear(s.image, q[0] * inv_z, q[1] * inv_z);
      if (v < 0.0f) return kMaxCost;
      const float weighted = w.weight[n] * v;
      sum_s += weighted;
      sum_ss += weighted * v;
      sum_rs += weighted * w.value[n];
      ++n;
      q[0] += di[0];
      q[1] += di[1];
      q[2] += di[2];
    }
    row[0] += dj[0];
    row[1] += dj[1];
    row[2] += dj[2];
  }
  const float inv_w = 1.0f / w.weight_sum;
  const float mean_s = sum_s * inv_w;
  const float variance_s = sum_ss * inv_w - mean_s * mean_s;
  if (variance_s < 1e-8f) return kMaxCost;
  const float covariance = sum_rs * inv_w - w.mean * mean_s;
  const float ncc = covariance / sqrtf(w.variance * variance_s);
  const float cost = 1.0f - ncc;
  return cost < 0.0f ? 0.0f : (cost > kMaxCost ? kMaxCost : cost);
}

// Forward-backward reprojection error of the point through the source's depth
// map, in reference pixels, clipped at the maximum.
TEGA_HD float reprojection_error(const SourceView& s, const ReferenceView& ref, const Parameters& p, int x, int y,
                                 const float* point) {
  if (!s.depth) return p.geometric_max_error;
  float ps[3];
  {
    float q[3];
    mat3_vec(s.R, point, q);
    q[0] += s.t[0];
    q[1] += s.t[1];
    q[2] += s.t[2];
    if (q[2] <= 0.0f) return p.geometric_max_error;
    mat3_vec(s.K, q, ps);
  }
  const int sx = static_cast<int>(floorf(ps[0] / ps[2] + 0.5f)), sy = static_cast<int>(floorf(ps[1] / ps[2] + 0.5f));
  if (sx < 0 || sy < 0 || sx >= s.image.width || sy >= s.image.height) return p.geometric_max_error;
  const float source_depth = s.depth[sy * s.image.width + sx];
  if (source_depth <= 0.0f) return p.geometric_max_error;
  float ray[3], back[3], q[3];
  pixel_ray(s.K_inverse, static_cast<float>(sx), static_cast<float>(sy), ray);
  for (int k = 0; k < 3; ++k) ray[k] *= source_depth;
  mat3_vec(s.R_back, ray, back);
  back[0] += s.t_back[0];
  back[1] += s.t_back[1];
  back[2] += s.t_back[2];
  if (back[2] <= 0.0f) return p.geometric_max_error;
  mat3_vec(ref.K, back, q);
  const float ex = q[0] / q[2] - static_cast<float>(x), ey = q[1] / q[2] - static_cast<float>(y);
  const float error = sqrtf(ex * ex + ey * ey);
  return error < p.geometric_max_error ? error : p.geometric_max_error;
}

// The hypothesis' cost: each source's 1 - NCC (plus the weighted reprojection
// error in a geometric pass), the mean of the best top_k.
TEGA_HD float hypothesis_cost(const ReferenceView& ref, const SourceView* sources, const Parameters& p,
                              const ReferenceWindow& w, int x, int y, float depth, const float* normal) {
  float ray[3];
  pixel_ray(ref.K_inverse, static_cast<float>(x), static_cast<float>(y), ray);
  const float point[3] = {depth * ray[0], depth * ray[1], depth * ray[2]};
  const float plane_offset = dot3(normal, point);
  if (plane_offset >= 0.0f) return kMaxCost + (p.geometric ? p.geometric_weight * p.geometric_max_error : 0.0f);
  float best[kMaxSources];
  int kept = 0;
  for (int k = 0; k < p.num_sources; ++k) {
    float H[9];
    plane_homography(sources[k], ref.K_inverse, normal, plane_offset, H);
    float cost = photometric_cost(sources[k], w, p, x, y, H);
    if (p.geometric) cost += p.geometric_weight * reprojection_error(sources[k], ref, p, x, y, point);
    // Insertion into the ascending list of the best top_k.
    int slot = kept < p.top_k ? kept++ : p.top_k;
    while (slot > 0 && best[slot - 1] > cost) {
      if (slot < p.top_k) best[slot] = best[slot - 1];
      --slot;
    }
    if (slot < p.top_k) best[slot] = cost;
  }
  float sum = 0;
  for (int k = 0; k < kept; ++k) sum += best[k];
  return kept > 0 ? sum / static_cast<float>(kept) : kMaxCost;
}

// ---- one pixel update of a red-black sweep ---------------------------------

struct Hypothesis {
  float depth;
  float normal[3];
  float cost;
};

TEGA_HD void consider(const ReferenceView& ref, const SourceView* sources, const Parameters& p,
                      const ReferenceWindow& w, int x, int y, const float* ray, float depth, const float* normal,
                      Hypothesis& best) {
  if (!(depth >= p.depth_min && depth <= p.depth_max) || !faces_camera(normal, ray)) return;
  const float cost = hypothesis_cost(ref, sources, p, w, x, y, depth, normal);
  if (cost < best.cost) {
    best.depth = depth;
    best.normal[0] = normal[0];
    best.normal[1] = normal[1];
    best.normal[2] = normal[2];
    best.cost = cost;
  }
}

// Neighbours of the other colour whose planes are tried at each pixel: the
// four adjacent pixels and four at distance 5 (odd offsets keep the colours apart).
TEGA_HD void neighbour_offset(int k, int& dx, int& dy) {
  const int offsets[8][2] = {{0, -1}, {0, 1}, {-1, 0}, {1, 0}, {0, -5}, {0, 5}, {-5, 0}, {5, 0}};
  dx = offsets[k][0];
  dy = offsets[k][1];
}

// Random initial hypothesis (scored).
TEGA_HD void initialise_pixel(const ReferenceView& ref, const SourceView* sources, const Parameters& p,
                              const PixelStates& s, int x, int y) {
  const int i = y * ref.image.width + x;
  if (ref.mask && !ref.mask[i]) {
    s.depth[i] = 0.0f;
    s.cost[i] = kMaxCost;
    return;
  }
  float ray[3];
  pixel_ray(ref.K_inverse, static_cast<float>(x), static_cast<float>(y), ray);
  const float depth = random_depth(p, random_uniform(p.seed, x, y, 0, 0));
  float normal[3];
  for (int attempt = 0; attempt < 4; ++attempt) {
    random_normal(ray, random_uniform(p.seed, x, y, 0, 1 + 2 * attempt), random_uniform(p.seed, x, y, 0, 2 + 2 * attempt),
                  normal);
    if (faces_camera(normal, ray)) break;
    normal[0] = -ray[0];  // head-on, when the draws keep grazing
    normal[1] = -ray[1];
    normal[2] = -ray[2];
    normalize3(normal);
  }
  ReferenceWindow w;
  reference_window(ref, p, x, y, w);
  s.depth[i] = depth;
  s.normal[3 * i + 0] = normal[0];
  s.normal[3 * i + 1] = normal[1];
  s.normal[3 * i + 2] = normal[2];
  s.cost[i] = hypothesis_cost(ref, sources, p, w, x, y, depth, normal);
}

// Propagation from the neighbours' planes, then random refinement around the
// best hypothesis with a range that halves every iteration.
TEGA_HD void update_pixel(const ReferenceView& ref, const SourceView* sources, const Parameters& p,
                          const PixelStates& s, int x, int y) {
  const int width = ref.image.width, height = ref.image.height;
  const int i = y * width + x;
  if (ref.mask && !ref.mask[i]) return;
  float ray[3];
  pixel_ray(ref.K_inverse, static_cast<float>(x), static_cast<float>(y), ray);
  ReferenceWindow w;
  reference_window(ref, p, x, y, w);

  Hypothesis best;
  best.depth = s.depth[i];
  best.normal[0] = s.normal[3 * i + 0];
  best.normal[1] = s.normal[3 * i + 1];
  best.normal[2] = s.normal[3 * i + 2];
  // The geometric term reads other views' maps, which change between passes.
  best.cost = p.geometric ? hypothesis_cost(ref, sources, p, w, x, y, best.depth, best.normal) : s.cost[i];

  // The neighbours' planes, the cheapest first (as their own pixels scored
  // them); only the best few are tried, since neighbours mostly agree.
  int order[8];
  float order_cost[8];
  int candidates = 0;
  for (int k = 0; k < 8; ++k) {
    int dx, dy;
    neighbour_offset(k, dx, dy);
    const int nx = x + dx, ny = y + dy;
    if (nx < 0 || ny < 0 || nx >= width || ny >= height || s.depth[ny * width + nx] <= 0.0f) continue;
    const float c = s.cost[ny * width + nx];
    int slot = candidates++;
    while (slot > 0 && order_cost[slot - 1] > c) {
      order[slot] = order[slot - 1];
      order_cost[slot] = order_cost[slot - 1];
      --slot;
    }
    order[slot] = k;
    order_cost[slot] = c;
  }
  if (candidates > kPropagationCandidates) candidates = kPropagationCandidates;
  for (int c = 0; c < candidates; ++c) {
    int dx, dy;
    neighbour_offset(order[c], dx, dy);
    const int nx = x + dx, ny = y + dy;
    const int j = ny * width + nx;
    const float neighbour_depth = s.depth[j];
    const float normal[3] = {s.normal[3 * j + 0], s.normal[3 * j + 1], s.normal[3 * j + 2]};
    float neighbour_ray[3];
    pixel_ray(ref.K_inverse, static_cast<float>(nx), static_cast<float>(ny), neighbour_ray);
    const float point[3] = {neighbour_depth * neighbour_ray[0], neighbour_depth * neighbour_ray[1],
                            neighbour_depth * neighbour_ray[2]};
    const float depth = plane_depth(point, normal, ray);
    // The plane this pixel already has: nothing to gain.
    if (fabsf(depth - best.depth) < 1e-6f * best.depth && dot3(normal, best.normal) > 0.999999f) continue;
    consider(ref, sources, p, w, x, y, ray, depth, normal, best);
  }

  // Refinement: a fresh depth, a fresh normal, and perturbations of both.
  const float range = 1.0f / static_cast<float>(1 << (p.iteration < 20 ? p.iteration + 1 : 21));
  const int it = p.iteration + 1;
  float u[8];
  for (int k = 0; k < 8; ++k) u[k] = random_uniform(p.seed, x, y, it, k);
  float random_n[3];
  random_normal(ray, u[0], u[1], random_n);
  const float current_n[3] = {best.normal[0], best.normal[1], best.normal[2]};
  const float current_depth = best.depth;
  const float perturbed_depth =
      current_depth * (1.0f + (2.0f * u[2] - 1.0f) * range * (p.depth_max - p.depth_min) / p.depth_max);
  float perturbed_n[3] = {current_n[0] + (2.0f * u[3] - 1.0f) * range, current_n[1] + (2.0f * u[4] - 1.0f) * range,
                          current_n[2] + (2.0f * u[5] - 1.0f) * range};
  normalize3(perturbed_n);
  consider(ref, sources, p, w, x, y, ray, random_depth(p, u[6]), current_n, best);
  consider(ref, sources, p, w, x, y, ray, current_depth, random_n, best);
  consider(ref, sources, p, w, x, y, ray, perturbed_depth, perturbed_n, best);
  consider(ref, sources, p, w, x, y, ray, current_depth, perturbed_n, best);
  consider(ref, sources, p, w, x, y, ray, perturbed_depth, current_n, best);

  s.depth[i] = best.depth;
  s.normal[3 * i + 0] = best.normal[0];
  s.normal[3 * i + 1] = best.normal[1];
  s.normal[3 * i + 2] = best.normal[2];
  s.cost[i] = best.cost;
}

}  // namespace tega::mvs::detail
