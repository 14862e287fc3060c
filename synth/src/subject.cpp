// A particular subject from the head model: identity shapes plus a shape
// detail that the model cannot express, so that trackers are tested on a
// head they can only approximate.
#include <algorithm>
#include <cmath>

#include "tega/core/error.h"
#include "tega/synth/head.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

// Where a face differs most between people, in face-frame units (right, up):
// nose, cheekbones, chin, brow ridge, jaw corners. Each bump's place and
// height are jittered by the seed.
const Eigen::Vector2d kBumpCentres[] = {{0, -0.65}, {0.75, -0.75}, {-0.75, -0.75}, {0, -1.75},
                                        {0, 0.75},  {1.0, -1.45},  {-1.0, -1.45}};

}  // namespace

void make_subject(Head& head, const std::vector<double>& identity, double detail_m, uint64_t seed) {
  BlendshapeModel& model = head.model;
  if (identity.size() > model.identity_deltas.size())
    throw Error(head.source, "head_identity has " + std::to_string(identity.size()) + " coefficients but the model has " +
                                 std::to_string(model.identity_deltas.size()) + " identity shapes");
  if (detail_m < 0) throw Error("head_shape_detail_m must not be negative");
  for (size_t i = 0; i < identity.size(); ++i)
    model.neutral.positions += static_cast<float>(identity[i]) * model.identity_deltas[i];
  finish_head(head);  // the eyes may have moved
  if (detail_m == 0) return;

  std::vector<char> is_eyeball(model.num_vertices(), 0);
  for (int f : head.eyeball_faces)
    for (int k = 0; k < 3; ++k) is_eyeball[model.neutral.faces(f, k)] = 1;
  const Vertices normals = model.neutral.vertex_normals();
  const FaceFrame& frame = head.frame;
  const Eigen::Vector3d eye_left = frame.to_face(frame.eye_left), eye_right = frame.to_face(frame.eye_right);

  struct Bump {
    Eigen::Vector2d centre;
    double sigma, height;
  };
  std::vector<Bump> bumps;
  int index = 0;
  for (const auto& centre : kBumpCentres) {
    const auto u = [&](int k) { return unit_from_hash(hash_of(seed, 0x5b, index, k)); };
    const double sign = u(0) < 0.5 ? -1.0 : 1.0;
    bumps.push_back({centre + 0.15 * Eigen::Vector2d(2 * u(1) - 1, 2 * u(2) - 1), 0.3 + 0.25 * u(3),
                     sign * (0.5 + 0.5 * u(4))});
    ++index;
  }
  Eigen::VectorXd offset = Eigen::VectorXd::Zero(model.num_vertices());
  for (int v = 0; v < model.num_vertices(); ++v) {
    if (is_eyeball[v]) continue;
    const Eigen::Vector3d p = frame.to_face(model.neutral.positions.row(v).cast<double>().transpose());
    if (p.z() < -1.0) continue;  // the back of the head stays as it is
    // The eyelids keep clear of the eyeballs they slide over.
    const double near_eye = std::min((p - eye_left).norm(), (p - eye_right).norm());
    const double weight = synth::smoothstep(0.3, 0.6, near_eye) * synth::smoothstep(-1.0, -0.4, p.z());
    for (const Bump& b : bumps)
      offset[v] += weight * b.height * std::exp(-(p.head<2>() - b.centre).squaredNorm() / (2 * b.sigma * b.sigma));
  }
  const double largest = offset.cwiseAbs().maxCoeff();
  if (largest == 0) return;
  offset *= detail_m / largest;
  for (int v = 0; v < model.num_vertices(); ++v)
    model.neutral.positions.row(v) += static_cast<float>(offset[v]) * normals.row(v);
  finish_head(head);
}

}  // namespace tega::synth
