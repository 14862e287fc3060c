#include "tega/uvd/uv_layout.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>

#include "tega/core/error.h"
#include "tega/uvd/uv_lookup.h"

namespace tega::uvd {
namespace {

// Lookups are exact at any resolution; a coarse grid builds in a fraction of
// the default's time, and these two lookups are built at every model's start.
constexpr double kOverlapTestResolution = 128;

// Whether a UV centroid of one group's triangles lies inside the other's.
bool centroids_inside(const Mesh& mesh, const std::vector<int32_t>& of, const std::vector<int32_t>& in) {
  const UvTriangleLookup other(mesh, {kOverlapTestResolution, 0.1}, in);
  at::Tensor centroids = at::empty({static_cast<int64_t>(of.size()), 2}, at::kDouble);
  auto c = centroids.accessor<double, 2>();
  for (size_t i = 0; i < of.size(); ++i)
    for (int axis = 0; axis < 2; ++axis) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += mesh.uvs(mesh.uv_faces(of[i], k), axis);
      c[static_cast<int64_t>(i)][axis] = sum / 3;
    }
  return (other.lookup(centroids).distance == 0).any().item<bool>();
}

Eigen::Vector2d uv_of(const Mesh& mesh, int32_t entry) { return mesh.uvs.row(entry).transpose().cast<double>(); }

struct UvBox {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = Eigen::Vector2d::Constant(-INFINITY);
  void add(const Eigen::Vector2d& p) { lo = lo.cwiseMin(p), hi = hi.cwiseMax(p); }
  Eigen::Vector2d size() const { return hi - lo; }
};

UvBox uv_box(const Mesh& mesh, const std::vector<int32_t>& faces) {
  UvBox box;
  for (const int32_t f : faces)
    for (int k = 0; k < 3; ++k) box.add(uv_of(mesh, mesh.uv_faces(f, k)));
  return box;
}

}  // namespace

SurfaceAreas surface_areas(const Mesh& mesh, const std::vector<int32_t>& faces) {
  SurfaceAreas a;
  for (const int32_t f : faces) {
    const Eigen::Vector3f p = mesh.positions.row(mesh.faces(f, 0)), q = mesh.positions.row(mesh.faces(f, 1)),
                          r = mesh.positions.row(mesh.faces(f, 2));
    a.world += 0.5 * (q - p).cross(r - p).norm();
    const Eigen::Vector2f s = mesh.uvs.row(mesh.uv_faces(f, 0)), t = mesh.uvs.row(mesh.uv_faces(f, 1)),
                          u = mesh.uvs.row(mesh.uv_faces(f, 2));
    const Eigen::Vector2f e1 = t - s, e2 = u - s;
    a.uv += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  return a;
}

std::vector<std::vector<int32_t>> uv_islands(const Mesh& mesh, const std::vector<int32_t>& faces) {
  std::vector<int32_t> parent(static_cast<size_t>(mesh.uvs.rows()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  for (const int32_t f : faces)
    for (int k = 1; k < 3; ++k) parent[root(mesh.uv_faces(f, k))] = root(mesh.uv_faces(f, 0));
  std::vector<int32_t> sorted = faces;
  std::sort(sorted.begin(), sorted.end());
  std::unordered_map<int32_t, size_t> island_of_root;
  std::vector<std::vector<int32_t>> islands;
  for (const int32_t f : sorted) {
    const auto [it, added] = island_of_root.emplace(root(mesh.uv_faces(f, 0)), islands.size());
    if (added) islands.emplace_back();
    islands[it->second].push_back(f);
  }
  return islands;
}

Mesh with_part_laid_apart(const Mesh& mesh, const std::vector<int32_t>& part) {
  if (!mesh.has_uvs()) throw Error("the template has no UVs to lay out");
  std::vector<bool> in_part(mesh.num_faces(), false);
  for (const int32_t f : part) {
    if (f < 0 || f >= mesh.num_faces())
      throw Error("face " + std::to_string(f) + " of the part to lay apart is out of range (the template has " +
                  std::to_string(mesh.num_faces()) + " faces)");
    in_part[f] = true;
  }
  std::vector<int32_t> moved, rest;
  for (int32_t f = 0; f < mesh.num_faces(); ++f) (in_part[f] ? moved : rest).push_back(f);
  const SurfaceAreas a_moved = surface_areas(mesh, moved), a_rest = surface_areas(mesh, rest);
  if (a_moved.uv <= 0 || a_rest.uv <= 0) return mesh;
  if (!centroids_inside(mesh, moved, rest) && !centroids_inside(mesh, rest, moved)) return mesh;
  double scale = a_moved.world > 0 ? std::sqrt((a_rest.uv / a_rest.world) / (a_moved.uv / a_moved.world)) : 1.0;

  const std::vector<std::vector<int32_t>> islands = uv_islands(mesh, moved);
  std::vector<UvBox> boxes;
  double largest = 0;
  for (const auto& island : islands) {
    boxes.push_back(uv_box(mesh, island));
    largest = std::max(largest, boxes.back().size().maxCoeff() * scale);
  }
  constexpr double kGap = 1.0 / 16;
  if (largest > 1 - 2 * kGap) scale *= (1 - 2 * kGap) / largest;

  // Rows of islands, bottom to top, in the unit tiles right of the rest.
  const UvBox rest_box = uv_box(mesh, rest);
  Eigen::Vector2d tile(std::ceil(rest_box.hi.x()), std::floor(rest_box.lo.y()));
  Eigen::Vector2d cursor = Eigen::Vector2d::Constant(kGap);
  double row_height = 0;
  std::vector<Eigen::Vector2d> origins;
  for (const UvBox& box : boxes) {
    const Eigen::Vector2d size = scale * box.size();
    if (cursor.x() + size.x() > 1 - kGap) cursor = {kGap, cursor.y() + row_height + kGap}, row_height = 0;
    if (cursor.y() + size.y() > 1 - kGap) tile.x() += 1, cursor = Eigen::Vector2d::Constant(kGap), row_height = 0;
    origins.push_back(tile + cursor);
    cursor.x() += size.x() + kGap;
    row_height = std::max(row_height, size.y());
  }

  // The moved triangles get UV entries of their own, appended in order of first use.
  Mesh out = mesh;
  std::vector<int32_t> copy_of(mesh.uvs.rows(), -1);
  std::vector<Eigen::Vector2d> added;
  for (size_t i = 0; i < islands.size(); ++i)
    for (const int32_t f : islands[i])
      for (int k = 0; k < 3; ++k) {
        const int32_t t = mesh.uv_faces(f, k);
        if (copy_of[t] < 0) {
          copy_of[t] = static_cast<int32_t>(mesh.uvs.rows() + static_cast<Eigen::Index>(added.size()));
          added.push_back(origins[i] + scale * (uv_of(mesh, t) - boxes[i].lo));
        }
        out.uv_faces(f, k) = copy_of[t];
      }
  out.uvs.conservativeResize(mesh.uvs.rows() + static_cast<Eigen::Index>(added.size()), 2);
  for (size_t i = 0; i < added.size(); ++i)
    out.uvs.row(mesh.uvs.rows() + static_cast<Eigen::Index>(i)) = added[i].cast<float>().transpose();
  // The old entries only the moved triangles used stay behind unused, so no index shifts.
  return out;
}

Mesh packed_in_unit_square(const Mesh& mesh) {
  if (!mesh.has_uvs()) throw Error("the template has no UVs to lay out");
  std::vector<int32_t> faces(mesh.num_faces());
  std::iota(faces.begin(), faces.end(), 0);
  const UvBox whole = uv_box(mesh, faces);
  if (faces.empty() || (whole.lo.minCoeff() >= 0 && whole.hi.maxCoeff() <= 1)) return mesh;

  // The occupied tiles in order of v then u, with their islands and the
  // extent of their content beyond the tile (a chart may overhang its tile).
  struct Tile {
    std::vector<size_t> islands;
    UvBox content;
  };
  const std::vector<std::vector<int32_t>> islands = uv_islands(mesh, faces);
  std::map<std::pair<double, double>, Tile> tiles;
  for (size_t i = 0; i < islands.size(); ++i) {
    const UvBox box = uv_box(mesh, islands[i]);
    const Eigen::Vector2d centre = 0.5 * (box.lo + box.hi);
    Tile& t = tiles[{std::floor(centre.y()), std::floor(centre.x())}];
    t.islands.push_back(i);
    t.content.add(box.lo), t.content.add(box.hi);
  }
  double pitch = 1;
  for (auto& [at, t] : tiles) {
    const Eigen::Vector2d origin(at.second, at.first);
    t.content.lo = (t.content.lo - origin).cwiseMin(Eigen::Vector2d::Zero());
    t.content.hi = (t.content.hi - origin).cwiseMax(Eigen::Vector2d::Ones());
    pitch = std::max(pitch, t.content.size().maxCoeff());
  }
  const int k = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(tiles.size())) - 1e-9));
  const double gap = pitch / 32, cell = pitch + gap, scale = 1 / (k * cell);

  Mesh out = mesh;
  std::vector<bool> done(mesh.uvs.rows(), false);
  int index = 0;
  for (const auto& [at, t] : tiles) {
    const Eigen::Vector2d origin(at.second, at.first);
    const Eigen::Vector2d cell_origin = cell * Eigen::Vector2d(index % k, index / k) + Eigen::Vector2d::Constant(gap / 2);
    ++index;
    for (const size_t i : t.islands)
      for (const int32_t f : islands[i])
        for (int c = 0; c < 3; ++c) {
          const int32_t e = mesh.uv_faces(f, c);
          if (done[e]) continue;
          done[e] = true;
          const Eigen::Vector2d uv = scale * (cell_origin + uv_of(mesh, e) - origin - t.content.lo);
          out.uvs.row(e) = uv.cast<float>().transpose();
        }
  }
  return out;
}

}  // namespace tega::uvd
