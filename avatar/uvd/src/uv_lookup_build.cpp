// Building the uv -> triangle grid. Every texel (cell) gets the list of
// triangles that contain, or are nearest to, some point of the cell:
//
//  1. Distance field at the cell corners: each corner gets a triangle and its
//     exact distance to it, seeded near every triangle and propagated by two
//     raster sweeps (as in 8SSEDT). The propagation may miss the true nearest
//     triangle; that only loosens the bound below, never breaks exactness,
//     because any triangle's distance is an upper bound of the nearest one.
//  2. A bound U per cell on the distance from any of its points to the
//     nearest triangle. Distance to a convex set is convex, so for one
//     triangle its maximum over the cell is at a corner: U = min over the
//     corners' triangles of the largest corner distance (also at most the
//     largest corner distance plus the half diagonal). U = 0 exactly when the
//     cell lies inside one triangle.
//  3. Candidates: every triangle overlapping the cell (separating axis test),
//     plus, where U > 0, every triangle within U of the cell. The latter are
//     found by a flood fill from each triangle's overlapped cells; it reaches
//     all the cells that need the triangle because the points whose nearest
//     triangle is T are star-shaped around their closest points on T.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "lookup_builder.h"
#include "tega/core/error.h"
#include "uv_geometry.h"

namespace tega::uvd {
namespace {

using namespace geometry;

// Stored distances are floats rounded up, so they stay upper bounds.
float round_up(double d) {
  float f = static_cast<float>(d);
  if (static_cast<double>(f) < d) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

struct Grid {
  int nx, ny;  // cells along u and v
  double ox, oy, tx, ty;
  Vec2 corner(int i, int j) const { return {ox + i * tx, oy + j * ty}; }
  Box cell(int i, int j) const { return {corner(i, j), corner(i + 1, j + 1)}; }
  // Index range [first, last] of the cells (or corners, with `count` = cells + 1) touching [lo, hi] in one axis.
  static std::pair<int, int> span(double lo, double hi, double origin, double size, int count) {
    const int first = std::clamp(static_cast<int>(std::floor((lo - origin) / size)), 0, count - 1);
    const int last = std::clamp(static_cast<int>(std::floor((hi - origin) / size)), 0, count - 1);
    return {first, last};
  }
};

struct CornerField {
  std::vector<int32_t> triangle;  // -1: not reached yet
  std::vector<float> distance;
};

CornerField corner_distance_field(const Grid& grid, const std::vector<Triangle>& tris,
                                  const std::vector<int32_t>& valid) {
  const int C = grid.nx + 1, CY = grid.ny + 1;
  CornerField field{std::vector<int32_t>(size_t(C) * CY, -1),
                    std::vector<float>(size_t(C) * CY, std::numeric_limits<float>::infinity())};
  auto relax = [&](int i, int j, int32_t t) {
    const size_t c = size_t(j) * C + i;
    if (t < 0 || t == field.triangle[c]) return;
    const float d = round_up(distance_to_triangle(grid.corner(i, j), tris[t]));
    if (d < field.distance[c]) {
      field.distance[c] = d;
      field.triangle[c] = t;
    }
  };
  for (int32_t t : valid) {
    const auto [xmin, xmax] = std::minmax({tris[t][0].x, tris[t][1].x, tris[t][2].x});
    const auto [ymin, ymax] = std::minmax({tris[t][0].y, tris[t][1].y, tris[t][2].y});
    // One corner beyond the bounding box on each side, so every corner of a
    // cell the triangle touches is seeded with it.
    const auto [i0, i1] = Grid::span(xmin - grid.tx, xmax + grid.tx, grid.ox, grid.tx, C);
    const auto [j0, j1] = Grid::span(ymin - grid.ty, ymax + grid.ty, grid.oy, grid.ty, CY);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) relax(i, j, t);
  }
  auto at = [&](int i, int j) {
    return (i < 0 || j < 0 || i >= C || j >= CY) ? -1 : field.triangle[size_t(j) * C + i];
  };
  for (int j = 0; j < CY; ++j)
    for (int i = 0; i < C; ++i) {
      relax(i, j, at(i - 1, j));
      relax(i, j, at(i - 1, j - 1));
      relax(i, j, at(i, j - 1));
      relax(i, j, at(i + 1, j - 1));
    }
  for (int j = CY - 1; j >= 0; --j)
    for (int i = C - 1; i >= 0; --i) {
      relax(i, j, at(i + 1, j));
      relax(i, j, at(i + 1, j + 1));
      relax(i, j, at(i, j + 1));
      relax(i, j, at(i - 1, j + 1));
    }
  return field;
}

std::vector<float> cell_bounds(const Grid& grid, const std::vector<Triangle>& tris, const CornerField& field) {
  const int R = grid.nx, C = R + 1;
  const double half_diagonal = 0.5 * std::hypot(grid.tx, grid.ty);
  std::vector<float> bound(size_t(R) * grid.ny);
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < R; ++i) {
      const int ci[4] = {i, i + 1, i + 1, i};
      const int cj[4] = {j, j, j + 1, j + 1};
      int32_t t[4];
      float d[4];
      for (int k = 0; k < 4; ++k) {
        t[k] = field.triangle[size_t(cj[k]) * C + ci[k]];
        d[k] = field.distance[size_t(cj[k]) * C + ci[k]];
      }
      float u = round_up(*std::max_element(d, d + 4) + half_diagonal);
      for (int k = 0; k < 4; ++k) {
        float largest = 0;
        for (int m = 0; m < 4; ++m)
          largest = std::max(largest, t[m] == t[k] ? d[m] : round_up(distance_to_triangle(grid.corner(ci[m], cj[m]), tris[t[k]])));
        u = std::min(u, largest);
      }
      bound[size_t(j) * R + i] = u;
    }
  return bound;
}

}  // namespace

void LookupBuilder::build(UvTriangleLookup& lookup, const Mesh& mesh, const UvLookupOptions& options,
                          const std::vector<int32_t>& active_faces) {
  if (!mesh.has_uvs() || mesh.uv_faces.rows() != mesh.faces.rows() || mesh.num_faces() == 0)
    throw Error("uv lookup: the template mesh has no UV triangles");
  if (!(options.resolution >= 1) || !(options.margin >= 0))
    throw Error("uv lookup: resolution must be >= 1 and margin >= 0");
  if (mesh.faces.minCoeff() < 0 || mesh.faces.maxCoeff() >= mesh.num_vertices() || mesh.uv_faces.minCoeff() < 0 ||
      mesh.uv_faces.maxCoeff() >= mesh.uvs.rows())
    throw Error("uv lookup: the template mesh has an index out of range");
  const int F = mesh.num_faces();
  std::vector<int32_t> candidates = active_faces;
  if (active_faces.empty()) {
    candidates.resize(F);
    for (int f = 0; f < F; ++f) candidates[f] = f;
  }
  for (int32_t f : candidates)
    if (f < 0 || f >= F) throw Error("uv lookup: active face " + std::to_string(f) + " out of range");

  std::vector<Triangle> tris(F);
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) tris[f][k] = {mesh.uvs(mesh.uv_faces(f, k), 0), mesh.uvs(mesh.uv_faces(f, k), 1)};
  Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
  for (int32_t f : candidates)
    for (const Vec2& c : tris[f]) {
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
    }
  const double extent = std::max(hi.x - lo.x, hi.y - lo.y);

  auto corners = at::zeros({F, 3, 2}, at::kDouble);
  auto inverse = at::zeros({F, 2, 2}, at::kDouble);
  auto gradient = at::zeros({F, 3, 2}, at::kDouble);
  auto area = at::zeros({F}, at::kDouble);
  auto c_acc = corners.accessor<double, 3>();
  auto i_acc = inverse.accessor<double, 3>();
  auto g_acc = gradient.accessor<double, 3>();
  auto a_acc = area.accessor<double, 1>();
  for (int f = 0; f < F; ++f) {
    const Triangle& t = tris[f];
    for (int k = 0; k < 3; ++k) {
      c_acc[f][k][0] = t[k].x;
      c_acc[f][k][1] = t[k].y;
    }
    const Vec2 e1 = t[1] - t[0], e2 = t[2] - t[0];
    const double det = cross(e1, e2);
    if (det == 0) continue;
    // [e1 e2]^-1: rows are ∂b1/∂(u,v) and ∂b2/∂(u,v).
    const double m[2][2] = {{e2.y / det, -e2.x / det}, {-e1.y / det, e1.x / det}};
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) {
        i_acc[f][r][c] = m[r][c];
        g_acc[f][r + 1][c] = m[r][c];
      }
    for (int c = 0; c < 2; ++c) g_acc[f][0][c] = -m[0][c] - m[1][c];
  }
  // Zero-area triangles have no barycentric map: they are never looked up.
  std::vector<int32_t> valid;
  for (int32_t f : candidates) {
    const double doubled_area = std::abs(cross(tris[f][1] - tris[f][0], tris[f][2] - tris[f][0]));
    if (doubled_area > 1e-12 * extent * extent && a_acc[f] == 0) {  // once, should active_faces repeat it
      a_acc[f] = 0.5 * doubled_area;
      valid.push_back(f);
    }
  }
  if (valid.empty()) throw Error("uv lookup: no active UV triangle of nonzero area");

  const double pad = options.margin;
  auto cells = [&](double size) { return std::max(1.0, std::ceil(size * options.resolution)); };
  const double cells_u = cells(hi.x - lo.x + 2 * pad), cells_v = cells(hi.y - lo.y + 2 * pad);
  if (cells_u * cells_v > double(1 << 28))
    throw Error("uv lookup: " + std::to_string(cells_u) + " x " + std::to_string(cells_v) +
                " texels is too many; lower the resolution");
  const int nx = static_cast<int>(cells_u), ny = static_cast<int>(cells_v);
  const Grid grid{nx, ny, lo.x - pad, lo.y - pad, (hi.x - lo.x + 2 * pad) / nx, (hi.y - lo.y + 2 * pad) / ny};

  const CornerField field = corner_distance_field(grid, tris, valid);
  const std::vector<float> bound = cell_bounds(grid, tris, field);

  std::vector<std::pair<int32_t, int32_t>> pairs;  // (cell, triangle)
  std::vector<int32_t> visited(size_t(nx) * ny, -1);  // last triangle whose fill reached the cell
  std::vector<int32_t> queue;
  for (int32_t t : valid) {
    queue.clear();
    const auto [xmin, xmax] = std::minmax({tris[t][0].x, tris[t][1].x, tris[t][2].x});
    const auto [ymin, ymax] = std::minmax({tris[t][0].y, tris[t][1].y, tris[t][2].y});
    const auto [i0, i1] = Grid::span(xmin, xmax, grid.ox, grid.tx, nx);
    const auto [j0, j1] = Grid::span(ymin, ymax, grid.oy, grid.ty, ny);
    // One cell more on each side: a vertex on a cell boundary touches both.
    for (int j = std::max(j0 - 1, 0); j <= std::min(j1 + 1, ny - 1); ++j)
      for (int i = std::max(i0 - 1, 0); i <= std::min(i1 + 1, nx - 1); ++i) {
        if (!overlaps(grid.cell(i, j), tris[t])) continue;
        const int32_t cell = j * nx + i;
        visited[cell] = t;
        pairs.emplace_back(cell, t);
        queue.push_back(cell);
      }
    for (size_t head = 0; head < queue.size(); ++head) {
      const int ci = queue[head] % nx, cj = queue[head] / nx;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int i = ci + di, j = cj + dj;
          if (i < 0 || j < 0 || i >= nx || j >= ny) continue;
          const int32_t cell = j * nx + i;
          if (visited[cell] == t) continue;
          visited[cell] = t;
          if (bound[cell] > 0 && distance_box_triangle(grid.cell(i, j), tris[t]) <= bound[cell]) {
            pairs.emplace_back(cell, t);
            queue.push_back(cell);
          }
        }
    }
  }

  // Counting sort of the pairs into per-cell lists.
  const int64_t num_cells = int64_t(nx) * ny;
  auto offsets = at::zeros({num_cells + 1}, at::kInt);
  auto* off = offsets.data_ptr<int32_t>();
  for (const auto& [cell, t] : pairs) ++off[cell + 1];
  for (int64_t c = 0; c < num_cells; ++c) {
    if (off[c + 1] == 0) throw Error("uv lookup: internal error, a texel has no candidate triangle");
    off[c + 1] += off[c];
  }
  auto triangles = at::empty({int64_t(pairs.size())}, at::kInt);
  auto* tri = triangles.data_ptr<int32_t>();
  std::vector<int32_t> fill(off, off + num_cells);
  for (const auto& [cell, t] : pairs) tri[fill[cell]++] = t;
  // The triangle containing the texel's centre goes first: the query tries it alone first.
  for (int64_t c = 0; c < num_cells; ++c) {
    const Vec2 centre{grid.ox + (c % nx + 0.5) * grid.tx, grid.oy + (c / nx + 0.5) * grid.ty};
    for (int32_t k = off[c]; k < off[c + 1]; ++k)
      if (contains(tris[tri[k]], centre)) {
        std::swap(tri[off[c]], tri[k]);
        break;
      }
  }

  lookup.cells_[0] = nx;
  lookup.cells_[1] = ny;
  lookup.origin_[0] = grid.ox;
  lookup.origin_[1] = grid.oy;
  lookup.texel_[0] = grid.tx;
  lookup.texel_[1] = grid.ty;
  lookup.cell_offsets_ = offsets;
  lookup.cell_triangles_ = triangles;
  auto faces = at::empty({F, 3}, at::kLong);
  auto f_acc = faces.accessor<int64_t, 2>();
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) f_acc[f][k] = mesh.faces(f, k);
  lookup.faces_ = faces;
  lookup.num_vertices_ = mesh.num_vertices();
  lookup.uv_area_ = area;
  lookup.double_ = {corners, inverse, gradient};
  lookup.float_ = {corners.to(at::kFloat), inverse.to(at::kFloat), gradient.to(at::kFloat)};
}

}  // namespace tega::uvd
