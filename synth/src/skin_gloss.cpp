#include "tega/synth/skin_gloss.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "tega/synth/appearance.h"

namespace tega::synth {
namespace {

constexpr float kMinGloss = 0.1f, kMaxGloss = 10.0f;

}  // namespace

SkinGloss::SkinGloss(const Head& head, const FineMeshMaker& maker, const ExpressionSpecularOptions& options)
    : head_(head), maker_(maker), options_(options) {
  if (!options.enabled()) return;
  neutral_area_ = skin_area(head.model.neutral.positions);
  const Mesh& fine = maker.fine_topology();
  lips_.resize(fine.num_vertices());
  for (int v = 0; v < fine.num_vertices(); ++v)
    lips_[v] = lip_weight(head.frame.to_face(fine.positions.row(v).cast<double>().transpose()).cast<float>());
  jaw_open_ = head.model.expression_index("jawOpen");
}

std::vector<double> SkinGloss::skin_area(const Vertices& coarse) const {
  const Triangles& faces = head_.model.neutral.faces;
  std::vector<double> area(coarse.rows(), 0.0);
  for (int f = 0; f < faces.rows(); ++f) {
    if (head_.triangle_eye[f] != 0) continue;
    const Eigen::Vector3d a = coarse.row(faces(f, 0)).cast<double>().transpose();
    const Eigen::Vector3d b = coarse.row(faces(f, 1)).cast<double>().transpose();
    const Eigen::Vector3d c = coarse.row(faces(f, 2)).cast<double>().transpose();
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[faces(f, k)] += third;
  }
  return area;
}

std::vector<float> SkinGloss::per_vertex(const Vertices& coarse, const std::vector<float>& expression,
                                         const FineFrame& fine) const {
  if (!options_.enabled()) return {};
  const std::vector<double> area = skin_area(coarse);
  std::vector<double> ratio(area.size(), 1.0);
  for (size_t v = 0; v < area.size(); ++v)
    if (neutral_area_[v] > 0) ratio[v] = area[v] / neutral_area_[v];
  const double jaw = jaw_open_ >= 0 && jaw_open_ < static_cast<int>(expression.size())
                         ? std::clamp<double>(expression[jaw_open_], 0.0, 1.0)
                         : 0.0;

  const Subdivision& subdivision = maker_.subdivision();
  std::vector<float> gloss(lips_.size());
  for (size_t v = 0; v < gloss.size(); ++v) {
    double stretch = 0;
    for (int k = 0; k < 3; ++k) stretch += subdivision.weight[v][k] * ratio[subdivision.source[v][k]];
    const double g = std::pow(stretch, options_.stretch_exponent) *
                     std::pow(double(fine.shading[v]), options_.crease_matte) *
                     (1 + options_.wet_lips * lips_[v] * jaw);
    gloss[v] = std::clamp(static_cast<float>(g), kMinGloss, kMaxGloss);
  }
  return gloss;
}

}  // namespace tega::synth
