#include "tega/core/triangle_distance_tree.h"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numeric>

namespace tega {
namespace {

constexpr int kLeafTriangles = 4;

double squared_distance_to_box(const Eigen::Vector3d& p, const Eigen::Vector3d& lower, const Eigen::Vector3d& upper) {
  return (lower - p).cwiseMax(p - upper).cwiseMax(0.0).squaredNorm();
}

// Whether the segment from + t d, 0 < t < 1, meets the box (slab test).
bool segment_meets_box(const Eigen::Vector3d& from, const Eigen::Vector3d& inverse_d, const Eigen::Vector3d& lower,
                       const Eigen::Vector3d& upper) {
  double enter = 0, leave = 1;
  for (int k = 0; k < 3; ++k) {
    double t0 = (lower[k] - from[k]) * inverse_d[k], t1 = (upper[k] - from[k]) * inverse_d[k];
    if (std::isnan(t0) || std::isnan(t1)) {  // along the slab's plane: inside it or not
      if (from[k] < lower[k] || from[k] > upper[k]) return false;
      continue;
    }
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
    if (enter > leave) return false;
  }
  return true;
}

// Möller-Trumbore: whether from + t d meets the triangle at some 0 < t < 1.
bool segment_meets_triangle(const Eigen::Vector3d& from, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return false;  // parallel to the plane
  const double inverse = 1 / det;
  const Eigen::Vector3d s = from - a;
  const double u = inverse * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = inverse * d.dot(q);
  if (v < 0 || u + v > 1) return false;
  const double t = inverse * e2.dot(q);
  return t > 0 && t < 1;
}

}  // namespace

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denominator = va + vb + vc;
  if (!(denominator > 0)) return a;  // a degenerate triangle: its vertices and edges were tried above
  return a + ab * (vb / denominator) + ac * (vc / denominator);
}

TriangleDistanceTree::TriangleDistanceTree(const Mesh& mesh, const std::vector<int>& faces) {
  std::vector<int> chosen = faces;
  if (chosen.empty()) {
    chosen.resize(size_t(mesh.num_faces()));
    std::iota(chosen.begin(), chosen.end(), 0);
  }
  triangles_.reserve(chosen.size());
  for (const int f : chosen) {
    const auto vertex = [&](int k) { return mesh.positions.row(mesh.faces(f, k)).transpose().cast<double>().eval(); };
    triangles_.push_back({vertex(0), vertex(1), vertex(2), f});
  }
  if (!triangles_.empty()) build(0, int(triangles_.size()));
}

int TriangleDistanceTree::build(int first, int count) {
  Node node;
  node.lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  node.upper = -node.lower;
  for (int i = first; i < first + count; ++i)
    for (const Eigen::Vector3d* v : {&triangles_[size_t(i)].a, &triangles_[size_t(i)].b, &triangles_[size_t(i)].c}) {
      node.lower = node.lower.cwiseMin(*v);
      node.upper = node.upper.cwiseMax(*v);
    }
  const int index = int(nodes_.size());
  nodes_.push_back(node);
  if (count <= kLeafTriangles) {
    nodes_[size_t(index)].first = first;
    nodes_[size_t(index)].count = count;
    return index;
  }
  // Split at the median centroid along the box's longest axis.
  int axis;
  (node.upper - node.lower).maxCoeff(&axis);
  const auto begin = triangles_.begin() + first;
  std::nth_element(begin, begin + count / 2, begin + count, [axis](const Triangle& s, const Triangle& t) {
    return s.a[axis] + s.b[axis] + s.c[axis] < t.a[axis] + t.b[axis] + t.c[axis];
  });
  const int left = build(first, count / 2);
  const int right = build(first + count / 2, count - count / 2);
  nodes_[size_t(index)].left = left;
  nodes_[size_t(index)].right = right;
  return index;
}

void TriangleDistanceTree::search(int index, const Eigen::Vector3d& point, double& best_squared, Closest& best) const {
  const Node& node = nodes_[size_t(index)];
  if (node.left < 0) {
    for (int i = node.first; i < node.first + node.count; ++i) {
      const Triangle& t = triangles_[size_t(i)];
      const Eigen::Vector3d on = closest_point_on_triangle(point, t.a, t.b, t.c);
      const double squared = (on - point).squaredNorm();
      if (squared < best_squared) {
        best_squared = squared;
        best.point = on;
        best.face = t.face;
      }
    }
    return;
  }
  int near = node.left, far = node.right;
  double near_squared = squared_distance_to_box(point, nodes_[size_t(near)].lower, nodes_[size_t(near)].upper);
  double far_squared = squared_distance_to_box(point, nodes_[size_t(far)].lower, nodes_[size_t(far)].upper);
  if (far_squared < near_squared) {
    std::swap(near, far);
    std::swap(near_squared, far_squared);
  }
  if (near_squared < best_squared) search(near, point, best_squared, best);
  if (far_squared < best_squared) search(far, point, best_squared, best);
}

TriangleDistanceTree::Closest TriangleDistanceTree::closest(const Eigen::Vector3d& point) const {
  double best_squared = std::numeric_limits<double>::infinity();
  Closest best;
  if (!nodes_.empty()) search(0, point, best_squared, best);
  best.distance = std::sqrt(best_squared);
  return best;
}

bool TriangleDistanceTree::crosses(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d d = to - from, inverse_d = d.cwiseInverse();
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[size_t(stack.back())];
    stack.pop_back();
    if (!segment_meets_box(from, inverse_d, node.lower, node.upper)) continue;
    if (node.left >= 0) {
      stack.push_back(node.left);
      stack.push_back(node.right);
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      const Triangle& t = triangles_[size_t(i)];
      if (segment_meets_triangle(from, d, t.a, t.b, t.c)) return true;
    }
  }
  return false;
}

double TriangleDistanceTree::distance(const Eigen::Vector3d& point) const { return closest(point).distance; }

}  // namespace tega
