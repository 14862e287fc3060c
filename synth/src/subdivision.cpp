// Midpoint (1-to-4, linear) subdivision that records, for every fine vertex,
// its blend of coarse vertices; the Phong tessellation and the per-frame
// positions are evaluated from those blends.
//
// Written here rather than with OpenMesh's subdividers (tega links OpenMesh,
// tega/core/openmesh.h), because none of them fits:
//  - LoopT, CompositeLoopT, Sqrt3T and CatmullClarkT are approximating: they
//    move the coarse vertices and make each fine vertex a blend of a whole
//    neighbourhood, not of one coarse triangle; ModifiedButterFlyT and the
//    Labsik-Greiner scheme interpolate but blend up to ten vertices around an
//    edge; MidpointT cuts corners (a face per original face and per original
//    vertex, on edge midpoints only; the original vertices go);
//    LongestEdgeT is adaptive. None records blend weights either.
//  - A halfedge mesh has one UV per halfedge and no UV numbering, so the
//    fine mesh's UV seams and `uv_faces` would have to be rebuilt afterwards,
//    and a coarse mesh with a non-manifold piece would not convert at all.
// Linear 1-to-4 midpoints that carry their weights take a page, below.

#include <unordered_map>

#include "tega/synth/fine_mesh.h"

namespace tega::synth {
namespace {

using Blend = std::array<std::pair<int32_t, float>, 3>;

Blend midpoint(const Blend& a, const Blend& b) {
  Blend out{};
  int n = 0;
  const auto add = [&](int32_t index, float w) {
    if (w == 0) return;
    for (int i = 0; i < n; ++i)
      if (out[i].first == index) {
        out[i].second += w;
        return;
      }
    out[n++] = {index, w};  // both lie in one coarse triangle: at most three indices
  };
  for (const auto& [i, w] : a) add(i, 0.5f * w);
  for (const auto& [i, w] : b) add(i, 0.5f * w);
  for (int i = n; i < 3; ++i) out[i] = {out[0].first, 0.0f};
  return out;
}

struct EdgeMidpoints {
  std::unordered_map<uint64_t, int32_t> index;
  int32_t get(int32_t a, int32_t b, const std::function<int32_t()>& create) {
    const uint64_t key = (uint64_t(std::min(a, b)) << 32) | uint32_t(std::max(a, b));
    auto [it, inserted] = index.try_emplace(key, 0);
    if (inserted) it->second = create();
    return it->second;
  }
};

}  // namespace

Subdivision subdivide(const Mesh& coarse, int levels) {
  std::vector<Blend> blends(coarse.num_vertices());
  for (int v = 0; v < coarse.num_vertices(); ++v) blends[v] = {{{v, 1.0f}, {v, 0.0f}, {v, 0.0f}}};
  std::vector<Eigen::Vector2f> uvs;
  for (int t = 0; t < coarse.uvs.rows(); ++t) uvs.push_back(coarse.uvs.row(t).transpose());
  std::vector<Eigen::Vector3i> faces, uv_faces;
  std::vector<int32_t> parent;
  const bool has_uvs = coarse.has_uvs();
  for (int f = 0; f < coarse.num_faces(); ++f) {
    faces.push_back(coarse.faces.row(f).transpose());
    uv_faces.push_back(has_uvs ? Eigen::Vector3i(coarse.uv_faces.row(f).transpose()) : Eigen::Vector3i::Zero());
    parent.push_back(f);
  }

  for (int level = 0; level < levels; ++level) {
    EdgeMidpoints vertex_mid, uv_mid;
    std::vector<Eigen::Vector3i> next_faces, next_uv_faces;
    std::vector<int32_t> next_parent;
    for (size_t f = 0; f < faces.size(); ++f) {
      Eigen::Vector3i m, mu;
      for (int k = 0; k < 3; ++k) {
        const int a = faces[f][k], b = faces[f][(k + 1) % 3];
        m[k] = vertex_mid.get(a, b, [&] {
          blends.push_back(midpoint(blends[a], blends[b]));
          return int32_t(blends.size() - 1);
        });
        if (has_uvs) {
          const int ua = uv_faces[f][k], ub = uv_faces[f][(k + 1) % 3];
          mu[k] = uv_mid.get(ua, ub, [&] {
            uvs.push_back(0.5f * (uvs[ua] + uvs[ub]));
            return int32_t(uvs.size() - 1);
          });
        }
      }
      // Corner triangles, then the middle one; m[k] sits on edge (k, k+1).
      const Eigen::Vector3i& c = faces[f];
      const Eigen::Vector3i& cu = uv_faces[f];
      next_faces.insert(next_faces.end(), {{c[0], m[0], m[2]}, {m[0], c[1], m[1]}, {m[2], m[1], c[2]}, {m[0], m[1], m[2]}});
      if (has_uvs)
        next_uv_faces.insert(next_uv_faces.end(),
                             {{cu[0], mu[0], mu[2]}, {mu[0], cu[1], mu[1]}, {mu[2], mu[1], cu[2]}, {mu[0], mu[1], mu[2]}});
      else
        next_uv_faces.insert(next_uv_faces.end(), 4, Eigen::Vector3i::Zero());
      next_parent.insert(next_parent.end(), 4, parent[f]);
    }
    faces = std::move(next_faces);
    uv_faces = std::move(next_uv_faces);
    parent = std::move(next_parent);
  }

  Subdivision s;
  s.fine.positions.resize(blends.size(), 3);
  for (size_t v = 0; v < blends.size(); ++v) {
    Eigen::Vector3f p = Eigen::Vector3f::Zero();
    std::array<int32_t, 3> src;
    std::array<float, 3> w;
    for (int k = 0; k < 3; ++k) {
      src[k] = blends[v][k].first;
      w[k] = blends[v][k].second;
      p += w[k] * coarse.positions.row(src[k]).transpose();
    }
    s.fine.positions.row(v) = p.transpose();
    s.source.push_back(src);
    s.weight.push_back(w);
  }
  s.fine.faces.resize(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) s.fine.faces.row(f) = faces[f].transpose();
  if (has_uvs) {
    s.fine.uvs.resize(uvs.size(), 2);
    for (size_t t = 0; t < uvs.size(); ++t) s.fine.uvs.row(t) = uvs[t].transpose();
    s.fine.uv_faces.resize(faces.size(), 3);
    for (size_t f = 0; f < faces.size(); ++f) s.fine.uv_faces.row(f) = uv_faces[f].transpose();
  }
  s.fine.triangle_polygon = std::move(parent);
  return s;
}

Vertices vertex_normals(const Vertices& positions, const Triangles& faces) {
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(positions.rows(), 3);
  for (int f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d a = positions.row(faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = positions.row(faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = positions.row(faces(f, 2)).cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);  // length = twice the area: area weighting
    for (int k = 0; k < 3; ++k) sum.row(faces(f, k)) += n.transpose();
  }
  Vertices out(positions.rows(), 3);
  for (int v = 0; v < positions.rows(); ++v) {
    const double len = sum.row(v).norm();
    out.row(v) = (len > 0 ? Eigen::RowVector3d(sum.row(v) / len) : Eigen::RowVector3d::Zero()).cast<float>();
  }
  return out;
}

}  // namespace tega::synth
