#pragma once
// Meshes and brute-force references shared by the uvd tests.

#include <ATen/ATen.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::uvd::test {

// A bumpy cylinder whose UV grid is cut open along one side (a seam: the
// first and last UV columns share positions), a cap fan on a separate UV disc
// (a seam all around), and a detached flap with a zero-area UV triangle. The
// UV layout has holes between the islands and jittered, irregular triangles.
inline Mesh seamed_mesh() {
  constexpr int kAround = 12, kUp = 6;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  Mesh m;
  std::vector<Eigen::Vector3f> p;
  std::vector<Eigen::Vector2f> t;
  std::vector<Eigen::Vector3i> f, ft;
  for (int j = 0; j <= kUp; ++j)
    for (int i = 0; i < kAround; ++i) {
      const double a = 2 * M_PI * i / kAround, z = 1.5 * j / kUp;
      const double r = 1 + 0.15 * std::sin(3 * a) + 0.1 * z * z;
      p.emplace_back(r * std::cos(a), r * std::sin(a), z + 0.05 * std::cos(2 * a));
    }
  const double du = 0.55 / kAround, dv = 0.8 / kUp;
  for (int j = 0; j <= kUp; ++j)
    for (int i = 0; i <= kAround; ++i) {
      const bool interior = i > 0 && i < kAround && j > 0 && j < kUp;
      t.emplace_back(0.05 + du * (i + (interior ? jitter(rng) : 0)), 0.1 + dv * (j + (interior ? jitter(rng) : 0)));
    }
  auto pos = [&](int i, int j) { return j * kAround + i % kAround; };
  auto tex = [&](int i, int j) { return j * (kAround + 1) + i; };
  for (int j = 0; j < kUp; ++j)
    for (int i = 0; i < kAround; ++i) {
      f.emplace_back(pos(i, j), pos(i + 1, j), pos(i + 1, j + 1));
      ft.emplace_back(tex(i, j), tex(i + 1, j), tex(i + 1, j + 1));
      f.emplace_back(pos(i, j), pos(i + 1, j + 1), pos(i, j + 1));
      ft.emplace_back(tex(i, j), tex(i + 1, j + 1), tex(i, j + 1));
    }
  // Cap: a fan over the top ring, laid out as a disc of its own.
  const int apex = static_cast<int>(p.size());
  p.emplace_back(0, 0, 1.85);
  const int center_uv = static_cast<int>(t.size());
  t.emplace_back(0.8, 0.65);
  for (int i = 0; i < kAround; ++i) {
    const double a = 2 * M_PI * i / kAround;
    t.emplace_back(0.8 + 0.12 * std::cos(a), 0.65 + 0.12 * std::sin(a));
  }
  for (int i = 0; i < kAround; ++i) {
    f.emplace_back(pos(i, kUp), pos(i + 1, kUp), apex);
    ft.emplace_back(center_uv + 1 + i, center_uv + 1 + (i + 1) % kAround, center_uv);
  }
  // Flap: two triangles away from the head, and one with collinear UVs.
  const int q = static_cast<int>(p.size());
  p.emplace_back(3.0, 0.0, 0.0);
  p.emplace_back(3.5, 0.0, 0.1);
  p.emplace_back(3.5, 0.5, 0.3);
  p.emplace_back(3.0, 0.5, 0.0);
  const int s = static_cast<int>(t.size());
  t.emplace_back(0.72, 0.1);
  t.emplace_back(0.95, 0.12);
  t.emplace_back(0.93, 0.33);
  t.emplace_back(0.7, 0.3);
  t.emplace_back(0.8, 0.2);  // on the segment between uv s+4 and s+5
  t.emplace_back(0.9, 0.3);
  f.emplace_back(q, q + 1, q + 2);
  ft.emplace_back(s, s + 1, s + 2);
  f.emplace_back(q, q + 2, q + 3);
  ft.emplace_back(s, s + 2, s + 3);
  f.emplace_back(q + 1, q + 2, q + 3);
  ft.emplace_back(s + 4, s + 5, s + 4);  // zero UV area
  auto to_matrix = [](const auto& rows, auto& out) {
    out.resize(static_cast<Eigen::Index>(rows.size()), out.cols());
    for (size_t r = 0; r < rows.size(); ++r) out.row(static_cast<Eigen::Index>(r)) = rows[r].transpose();
  };
  to_matrix(p, m.positions);
  to_matrix(t, m.uvs);
  to_matrix(f, m.faces);
  to_matrix(ft, m.uv_faces);
  return m;
}

// ICT-FaceKit's face and head-and-neck triangles (source polygons [0, 11144)),
// whose UV islands overlap nothing else.
inline std::vector<int32_t> ict_head_faces(const Mesh& ict) {
  std::vector<int32_t> faces;
  for (int f = 0; f < ict.num_faces(); ++f)
    if (ict.triangle_polygon.at(f) < 11144) faces.push_back(f);
  return faces;
}

inline int degenerate_face_of_seamed_mesh(const Mesh& m) { return m.num_faces() - 1; }

inline Eigen::Vector2d uv_corner(const Mesh& m, int face, int k) {
  return m.uvs.row(m.uv_faces(face, k)).transpose().cast<double>();
}

inline double uv_area(const Mesh& m, int face) {
  const Eigen::Vector2d e1 = uv_corner(m, face, 1) - uv_corner(m, face, 0);
  const Eigen::Vector2d e2 = uv_corner(m, face, 2) - uv_corner(m, face, 0);
  return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
}

// Closest point on a triangle by brute force: the point itself when inside,
// else the best of the three edges. Independent of the library's code.
inline double distance_to_uv_triangle(const Mesh& m, int face, const Eigen::Vector2d& p) {
  const Eigen::Vector2d a = uv_corner(m, face, 0), b = uv_corner(m, face, 1), c = uv_corner(m, face, 2);
  auto side = [&](const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    const Eigen::Vector2d e = y - x, w = p - x;
    return e.x() * w.y() - e.y() * w.x();
  };
  const double s0 = side(a, b), s1 = side(b, c), s2 = side(c, a);
  if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) return 0;
  auto segment = [&](const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
    const double t = std::clamp((p - x).dot(y - x) / (y - x).squaredNorm(), 0.0, 1.0);
    return (p - (x + t * (y - x))).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

inline double nearest_uv_distance(const Mesh& m, const Eigen::Vector2d& p) {
  double best = INFINITY;
  for (int face = 0; face < m.num_faces(); ++face)
    if (uv_area(m, face) > 1e-12) best = std::min(best, distance_to_uv_triangle(m, face, p));
  return best;
}

// Area-weighted unit vertex normals, computed without the library.
inline Eigen::MatrixXd reference_normals(const Eigen::MatrixXd& v, const Mesh& m) {
  Eigen::MatrixXd n = Eigen::MatrixXd::Zero(v.rows(), 3);
  for (int face = 0; face < m.num_faces(); ++face) {
    const Eigen::Vector3d a = v.row(m.faces(face, 0)), b = v.row(m.faces(face, 1)), c = v.row(m.faces(face, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n.row(m.faces(face, k)) += cross.transpose();
  }
  n.rowwise().normalize();
  return n;
}

// A non-rigid pose of the template: bend, stretch and shift, so that J_F is no rotation.
inline Eigen::MatrixXd posed_vertices(const Mesh& m) {
  Eigen::MatrixXd v = m.positions.cast<double>();
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const double x = v(i, 0), y = v(i, 1), z = v(i, 2);
    v.row(i) << 1.3 * x + 0.2 * z * z, 0.8 * y + 0.1 * std::sin(2 * x), z + 0.1 * x * y + 0.3;
  }
  return v;
}

inline at::Tensor to_tensor(const Eigen::MatrixXd& m) {
  auto t = at::empty({m.rows(), m.cols()}, at::kDouble);
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) t[r][c] = m(r, c);
  return t;
}

// n points per listed face, with random barycentrics at least `margin` from every edge.
struct FacePoints {
  std::vector<int> face;
  at::Tensor barycentrics;  // [N,3] double
  at::Tensor uv;            // [N,2] double
};
inline FacePoints points_in_faces(const Mesh& m, const std::vector<int>& faces, int per_face, double margin,
                                  unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  FacePoints out;
  const int n = static_cast<int>(faces.size()) * per_face;
  out.barycentrics = at::empty({n, 3}, at::kDouble);
  out.uv = at::empty({n, 2}, at::kDouble);
  auto b_acc = out.barycentrics.accessor<double, 2>();
  auto uv_acc = out.uv.accessor<double, 2>();
  int row = 0;
  for (int face : faces)
    for (int k = 0; k < per_face; ++k, ++row) {
      double b[3], sum = 0;
      for (double& x : b) sum += (x = -std::log(1 - unit(rng)));  // uniform on the simplex
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int c = 0; c < 3; ++c) {
        b[c] = margin + (1 - 3 * margin) * b[c] / sum;
        b_acc[row][c] = b[c];
        uv += b[c] * uv_corner(m, face, c);
      }
      uv_acc[row][0] = uv.x();
      uv_acc[row][1] = uv.y();
      out.face.push_back(face);
    }
  return out;
}

}  // namespace tega::uvd::test
