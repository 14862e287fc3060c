#pragma once
// One query of the uv -> triangle lookup (uv_lookup.h), shared by the CPU
// loop and the CUDA kernel: the query's texel, then its candidate triangles
// in order. The first is the triangle containing the texel's centre where
// one does, so most queries inside the layout stop there; the others keep
// the first of the closest candidates.

#include <cstdint>

#include "scalar_math.h"
#include "tega/core/host_device.h"

namespace tega::uvd::uv_lookup {

// The lookup's grid and per-triangle tables, contiguous, in the query's dtype.
template <typename T>
struct Grid {
  const int32_t* cell_offsets = nullptr;    // [cells+1] into cell_triangles
  const int32_t* cell_triangles = nullptr;  // candidates grouped by cell (≥ 1 each)
  const T* corners = nullptr;               // [F,3,2] uv of the corners
  const T* inverse = nullptr;               // [F,2,2] (u,v) - corner 0 -> (b1,b2)
  int cells[2] = {0, 0};                    // texels along u and v; texel (i,j) is cell j*cells[0]+i
  T origin[2] = {0, 0};
  T texel[2] = {1, 1};
};

// Where the answers go, one row per query.
template <typename T>
struct Answers {
  int64_t* triangle;  // [N]
  T* barycentrics;    // [N,3]
  T* uv;              // [N,2] the query, or its closest valid point
  T* distance;        // [N]
};

template <typename T>
struct Closest {
  T distance2;
  T point[2];
  T barycentrics[3];
};

// The closest point of (u, v) on triangle f: the query itself where its
// barycentrics are all ≥ 0, else the closest point of the nearest edge
// (edge k runs from corner k to corner k+1; the first of equally near ones).
template <typename T>
TEGA_HD Closest<T> closest_point(const Grid<T>& g, int64_t f, T u, T v) {
  const T* c = g.corners + 6 * f;
  const T* m = g.inverse + 4 * f;
  const T du = u - c[0], dv = v - c[1];
  const T b1 = m[0] * du + m[1] * dv, b2 = m[2] * du + m[3] * dv;
  const T b0 = T(1) - (b1 + b2);
  if (b0 >= T(0) && b1 >= T(0) && b2 >= T(0)) return {T(0), {u, v}, {b0, b1, b2}};
  Closest<T> best{T(0), {u, v}, {0, 0, 0}};
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) {
    const int next = k == 2 ? 0 : k + 1;
    const T ex = c[2 * next] - c[2 * k], ey = c[2 * next + 1] - c[2 * k + 1];
    T s = ((u - c[2 * k]) * ex + (v - c[2 * k + 1]) * ey) / (ex * ex + ey * ey);
    s = s < T(0) ? T(0) : (s > T(1) ? T(1) : s);
    const T px = c[2 * k] + s * ex, py = c[2 * k + 1] + s * ey;
    const T d2 = (u - px) * (u - px) + (v - py) * (v - py);
    if (k == 0 || d2 < best.distance2) {
      best.distance2 = d2;
      best.point[0] = px;
      best.point[1] = py;
      best.barycentrics[0] = best.barycentrics[1] = best.barycentrics[2] = T(0);
      best.barycentrics[k] = T(1) - s;
      best.barycentrics[next] = s;
    }
  }
  return best;
}

// The texel of one coordinate; beyond the grid (or NaN), the nearest border texel.
template <typename T>
TEGA_HD int64_t texel_of(T x, T origin, T size, int cells) {
  const T t = math_floor((x - origin) / size);
  if (!(t >= T(0))) return 0;
  return t > T(cells - 1) ? cells - 1 : int64_t(t);
}

// Answers query i of uv [N,2].
template <typename T>
TEGA_HD void lookup_point(const Grid<T>& g, const T* uv, int64_t i, const Answers<T>& out) {
  const T u = uv[2 * i], v = uv[2 * i + 1];
  const int64_t cell = texel_of(v, g.origin[1], g.texel[1], g.cells[1]) * g.cells[0] +
                       texel_of(u, g.origin[0], g.texel[0], g.cells[0]);
  const int32_t begin = g.cell_offsets[cell], end = g.cell_offsets[cell + 1];
  int64_t triangle = g.cell_triangles[begin];
  Closest<T> best = closest_point(g, triangle, u, v);
  for (int32_t k = begin + 1; k < end && best.distance2 > T(0); ++k) {
    const int64_t candidate = g.cell_triangles[k];
    const Closest<T> c = closest_point(g, candidate, u, v);
    if (c.distance2 < best.distance2) {
      best = c;
      triangle = candidate;
    }
  }
  out.triangle[i] = triangle;
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) out.barycentrics[3 * i + k] = best.barycentrics[k];
  out.uv[2 * i] = best.point[0];
  out.uv[2 * i + 1] = best.point[1];
  out.distance[i] = math_sqrt(best.distance2);
}

}  // namespace tega::uvd::uv_lookup
