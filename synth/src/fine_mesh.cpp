#include <algorithm>
#include <cmath>
#include <numbers>

#include "tega/synth/fine_mesh.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

// How far Phong tessellation pulls a midpoint towards the vertices' tangent
// planes (Boubekeur and Alexa's recommended 3/4).
constexpr float kPhongShape = 0.75f;
// Regions' contributions below this are dropped from the per-vertex lists.
constexpr float kNegligible = 1e-4f;

// Window x profile of a region at a point of the neutral face (face frame units).
double region_weight(const WrinkleRegion& r, const Eigen::Vector3d& face_point) {
  const Eigen::Vector2d d = face_point.head<2>() - r.centre;
  const double c = std::cos(r.angle), s = std::sin(r.angle);
  const double along = c * d.x() + s * d.y(), across = -s * d.x() + c * d.y();
  const double window = std::exp(-0.5 * (std::pow(along / r.sigma.x(), 2) + std::pow(across / r.sigma.y(), 2)));
  double profile;
  if (r.period > 0) {
    // Furrows, gently wavy along their length; the cube sharpens the valleys.
    const double phase = 2 * std::numbers::pi * (across + 0.03 * std::sin(6.0 * along)) / r.period;
    profile = std::pow(0.5 * (1 + std::cos(phase)), 3);
  } else {
    profile = std::exp(-std::pow(across / r.groove_width, 2));
  }
  return window * profile;
}

}  // namespace

FineMeshMaker::FineMeshMaker(const Head& head, const WrinkleSettings& settings)
    : head_(head), settings_(settings), subdivision_(subdivide(head.model.neutral, settings.subdivisions)) {
  const Mesh& fine = subdivision_.fine;
  for (int f = 0; f < fine.num_faces(); ++f) fine_triangle_eye_.push_back(head.triangle_eye[fine.triangle_polygon[f]]);

  // Wrinkles form on the skin, on surfaces that face forwards.
  std::vector<char> on_skin(fine.num_vertices(), 0);
  for (int f = 0; f < fine.num_faces(); ++f)
    if (fine_triangle_eye_[f] == 0)
      for (int k = 0; k < 3; ++k) on_skin[fine.faces(f, k)] = 1;
  const Vertices normals = vertex_normals(fine.positions, fine.faces);
  const Eigen::Vector3d forward = head.frame.axes.col(2);

  for (const WrinkleRegion& region : head.wrinkles) {
    RegionWeights w;
    for (const auto& name : region.drivers) {
      const int index = head.model.expression_index(name);
      if (index >= 0) w.drivers.push_back(index);
    }
    if (w.drivers.empty()) continue;
    for (int v = 0; v < fine.num_vertices(); ++v) {
      if (!on_skin[v]) continue;
      const Eigen::Vector3d p = fine.positions.row(v).cast<double>().transpose();
      const double facing = smoothstep(0.2, 0.5, normals.row(v).cast<double>().dot(forward.transpose()));
      const double weight = facing * region_weight(region, head.frame.to_face(p));
      if (weight < kNegligible) continue;
      w.vertices.push_back(v);
      w.depth.push_back(float(weight * region.depth_scale * settings.depth_m));
      w.darkening.push_back(float(weight * region.darkening_scale * settings.darkening));
    }
    regions_.push_back(std::move(w));
    region_names_.push_back(region.name);
  }
}

std::vector<double> FineMeshMaker::region_activations(const std::vector<float>& expression) const {
  std::vector<double> out;
  for (const RegionWeights& r : regions_) {
    double a = 0;
    for (int i : r.drivers)
      if (i < static_cast<int>(expression.size())) a = std::max<double>(a, expression[i]);
    out.push_back(std::clamp(a, 0.0, 1.0));
  }
  return out;
}

FineFrame FineMeshMaker::make(const Vertices& coarse, const std::vector<float>& expression) const {
  const Mesh& fine = subdivision_.fine;
  const Vertices coarse_normals = vertex_normals(coarse, head_.model.neutral.faces);
  const int n = fine.num_vertices();

  std::vector<float> depth(n, 0.0f), darkening(n, 0.0f);
  const std::vector<double> activation = region_activations(expression);
  for (size_t r = 0; r < regions_.size(); ++r) {
    if (activation[r] <= 0) continue;
    const RegionWeights& w = regions_[r];
    for (size_t i = 0; i < w.vertices.size(); ++i) {
      depth[w.vertices[i]] += float(activation[r]) * w.depth[i];
      darkening[w.vertices[i]] += float(activation[r]) * w.darkening[i];
    }
  }

  FineFrame out;
  out.positions.resize(n, 3);
  out.shading.resize(n);
  for (int v = 0; v < n; ++v) {
    const auto& src = subdivision_.source[v];
    const auto& wt = subdivision_.weight[v];
    Eigen::Vector3f p = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) {
      p += wt[k] * coarse.row(src[k]).transpose();
      normal += wt[k] * coarse_normals.row(src[k]).transpose();
    }
    Eigen::Vector3f projected = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f vk = coarse.row(src[k]).transpose(), nk = coarse_normals.row(src[k]).transpose();
      projected += wt[k] * (p - (p - vk).dot(nk) * nk);
    }
    p = (1 - kPhongShape) * p + kPhongShape * projected;
    if (normal.squaredNorm() > 0) normal.normalize();
    out.positions.row(v) = (p - depth[v] * normal).transpose();
    out.shading[v] = 1.0f - std::min(0.95f, darkening[v]);
  }
  out.normals = vertex_normals(out.positions, fine.faces);
  return out;
}

}  // namespace tega::synth
