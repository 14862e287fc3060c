#pragma once
// Exact closest points on a triangle mesh: a bounding-volume hierarchy over
// the triangles, searched nearest box first and pruned by the best distance
// found so far, so the answer is the exact point-to-triangle minimum. Used to
// score surfaces (mvs/) and to find the scan under a model (tracking/); the
// same hierarchy answers whether a line of sight is blocked (tracking/).

#include <Eigen/Core>
#include <vector>

#include "tega/core/mesh.h"

namespace tega {

class TriangleDistanceTree {
 public:
  // `faces`: the triangles of `mesh` to search (empty: all of them).
  explicit TriangleDistanceTree(const Mesh& mesh, const std::vector<int>& faces = {});
  bool empty() const { return triangles_.empty(); }
  // Infinity when the tree is empty.
  double distance(const Eigen::Vector3d& point) const;

  struct Closest {
    Eigen::Vector3d point;
    int face = -1;  // of the mesh; -1 when the tree is empty
    double distance = 0;
  };
  Closest closest(const Eigen::Vector3d& point) const;

  // Whether a triangle crosses the segment from `from` to `to` (ends excluded).
  bool crosses(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;

 private:
  struct Triangle {
    Eigen::Vector3d a, b, c;
    int face = 0;
  };
  struct Node {
    Eigen::Vector3d lower, upper;
    int first = 0, count = 0;  // a leaf's triangles
    int left = -1, right = -1;
  };
  int build(int first, int count);
  void search(int node, const Eigen::Vector3d& point, double& best_squared, Closest& best) const;

  std::vector<Triangle> triangles_;
  std::vector<Node> nodes_;
};

// The closest point of triangle (a, b, c) to p, exactly (by Voronoi regions).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

}  // namespace tega
