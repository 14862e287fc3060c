#pragma once
// Exact 2D geometry in double precision for building the uv lookup grid.

#include <algorithm>
#include <array>
#include <cmath>

namespace tega::uvd::geometry {

struct Vec2 {
  double x = 0, y = 0;
};
inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
inline double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }

using Triangle = std::array<Vec2, 3>;

struct Box {
  Vec2 lo, hi;
};

inline double distance2_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 e = b - a;
  const double len2 = dot(e, e);
  const double t = len2 > 0 ? std::clamp(dot(p - a, e) / len2, 0.0, 1.0) : 0.0;
  const Vec2 d{p.x - (a.x + t * e.x), p.y - (a.y + t * e.y)};
  return dot(d, d);
}

// Either winding; a point on the boundary is inside.
inline bool contains(const Triangle& t, Vec2 p) {
  const double c0 = cross(t[1] - t[0], p - t[0]);
  const double c1 = cross(t[2] - t[1], p - t[1]);
  const double c2 = cross(t[0] - t[2], p - t[2]);
  return (c0 >= 0 && c1 >= 0 && c2 >= 0) || (c0 <= 0 && c1 <= 0 && c2 <= 0);
}

inline double distance_to_triangle(Vec2 p, const Triangle& t) {
  if (contains(t, p)) return 0;
  return std::sqrt(std::min({distance2_to_segment(p, t[0], t[1]), distance2_to_segment(p, t[1], t[2]),
                             distance2_to_segment(p, t[2], t[0])}));
}

inline double distance_to_box(Vec2 p, const Box& b) {
  const double dx = std::max({b.lo.x - p.x, 0.0, p.x - b.hi.x});
  const double dy = std::max({b.lo.y - p.y, 0.0, p.y - b.hi.y});
  return std::sqrt(dx * dx + dy * dy);
}

inline std::array<Vec2, 4> corners(const Box& b) {
  return {Vec2{b.lo.x, b.lo.y}, Vec2{b.hi.x, b.lo.y}, Vec2{b.hi.x, b.hi.y}, Vec2{b.lo.x, b.hi.y}};
}

// Separating axis test: the box's axes and the triangle's edge normals.
inline bool overlaps(const Box& b, const Triangle& t) {
  const auto [xmin, xmax] = std::minmax({t[0].x, t[1].x, t[2].x});
  const auto [ymin, ymax] = std::minmax({t[0].y, t[1].y, t[2].y});
  if (xmax < b.lo.x || xmin > b.hi.x || ymax < b.lo.y || ymin > b.hi.y) return false;
  const auto box_corners = corners(b);
  for (int e = 0; e < 3; ++e) {
    const Vec2 a = t[e], edge = t[(e + 1) % 3] - a;
    const Vec2 normal{-edge.y, edge.x};
    const double opposite = dot(normal, t[(e + 2) % 3] - a);  // the triangle spans [0, opposite]
    double box_min = INFINITY, box_max = -INFINITY;
    for (const Vec2& c : box_corners) {
      const double s = dot(normal, c - a);
      box_min = std::min(box_min, s);
      box_max = std::max(box_max, s);
    }
    if (box_max < std::min(0.0, opposite) || box_min > std::max(0.0, opposite)) return false;
  }
  return true;
}

// Between disjoint convex polygons the distance is reached at a vertex of one of them.
inline double distance_box_triangle(const Box& b, const Triangle& t) {
  if (overlaps(b, t)) return 0;
  double d = INFINITY;
  for (const Vec2& c : corners(b)) d = std::min(d, distance_to_triangle(c, t));
  for (const Vec2& v : t) d = std::min(d, distance_to_box(v, b));
  return d;
}

}  // namespace tega::uvd::geometry
