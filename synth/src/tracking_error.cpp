// The tracking-error model of the dataset's meshes (tracking_error.h).
#include "tega/synth/tracking_error.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "tega/core/error.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

// Salts that keep each error's draws apart from every other use of the seed.
constexpr uint64_t kOffsetSalt = 0x7e0ff5e7, kMisfitSalt = 0x7e3157f1, kShapeSalt = 0x75a9e3f1;

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

void validate_tracking_error_options(const TrackingErrorOptions& o) {
  if (o.offset_m < 0) throw Error("tracking_error.offset_m must not be negative");
  if (!(o.offset_scale > 0)) throw Error("tracking_error.offset_scale must be positive");
  if (o.offset_bumps < 1) throw Error("tracking_error.offset_bumps must be at least 1");
  if (o.period_frames < 1) throw Error("tracking_error.period_frames must be at least 1");
  if (o.lag < 0) throw Error("tracking_error.lag must not be negative");
  if (o.eyelid_misfit < 0 || o.lip_misfit < 0)
    throw Error("tracking_error.eyelid_misfit and lip_misfit must not be negative");
  if (o.eyelid_gain < 0 || o.lip_gain < 0) throw Error("tracking_error.eyelid_gain and lip_gain must not be negative");
  if (o.shape_misfit < 0) throw Error("tracking_error.shape_misfit must not be negative");
}

TrackingError::TrackingError(const Head& head, const TrackingErrorOptions& options, uint64_t seed)
    : head_(head), options_(options), seed_(seed) {
  validate_tracking_error_options(options_);

  const BlendshapeModel& model = head.model;
  const Mesh& neutral = model.neutral;
  vertex_eye_.assign(model.num_vertices(), 0);
  for (size_t f = 0; f < head.triangle_eye.size(); ++f)
    if (head.triangle_eye[f])
      for (int k = 0; k < 3; ++k) vertex_eye_[neutral.faces(f, k)] = head.triangle_eye[f];
  box_min_ = Eigen::Vector3d::Constant(1e30);
  box_max_ = Eigen::Vector3d::Constant(-1e30);
  for (int v = 0; v < model.num_vertices(); ++v) {
    if (vertex_eye_[v]) continue;
    const Eigen::Vector3d p = head.frame.to_face(neutral.positions.row(v).cast<double>().transpose());
    box_min_ = box_min_.cwiseMin(p);
    box_max_ = box_max_.cwiseMax(p);
  }
  blink_left_ = model.expression_index("eyeBlink_L");
  blink_right_ = model.expression_index("eyeBlink_R");
  is_lip_.assign(model.expression_names.size(), 0);
  for (size_t e = 0; e < model.expression_names.size(); ++e)
    is_lip_[e] = starts_with(model.expression_names[e], "jaw") || starts_with(model.expression_names[e], "mouth");
  // Drawn per subject and expression, not per take or frame: the tracker's
  // model is the same in every frame.
  if (options_.shape_misfit > 0)
    for (const std::string& name : model.expression_names) {
      Eigen::VectorXd gain = smooth_draw(hash_of(seed_, kShapeSalt, hash_string(name.c_str())), 0, 1).col(0);
      for (int v = 0; v < model.num_vertices(); ++v)
        if (vertex_eye_[v]) gain[v] = 0;
      shape_gains_.push_back(std::move(gain));
    }
}

void TrackingError::keys(int frame, int& key, double& weight) const {
  const int period = options_.period_frames;
  key = frame / period;
  weight = smoothstep(0.0, 1.0, double(frame % period) / period);
}

TrackingError::LagSource TrackingError::lag_source(int frame, int frames) const {
  const double source = std::max(0.0, frame - options_.lag);
  LagSource s;
  s.first = std::min(static_cast<int>(std::floor(source)), frames - 1);
  s.weight = source - s.first;
  s.second = std::min(s.first + 1, frames - 1);
  if (s.second == s.first) s.weight = 0;
  return s;
}

std::vector<float> TrackingError::misfit(const std::vector<float>& expression, const std::vector<int>& driven,
                                         const std::string& take, int frame) const {
  const TrackingErrorOptions& o = options_;
  std::vector<float> out = expression;
  int key = 0;
  double weight = 0;
  keys(frame, key, weight);
  const uint64_t take_seed = hash_of(seed_, kMisfitSalt, hash_string(take.c_str()));
  const auto perturb = [&](int index, double gain, double amplitude) {
    if (index < 0 || index >= static_cast<int>(out.size())) return;
    double c = out[index];
    if (gain == 1.0 && amplitude == 0.0) return;
    const auto draw = [&](int k) { return 2.0 * uniform(take_seed, k, index) - 1.0; };
    const double error = (1 - weight) * draw(key) + (weight > 0 ? weight * draw(key + 1) : 0.0);
    c = std::clamp(gain * c + amplitude * error, 0.0, 1.0);
    out[index] = static_cast<float>(c);
  };
  perturb(blink_left_, o.eyelid_gain, o.eyelid_misfit);
  perturb(blink_right_, o.eyelid_gain, o.eyelid_misfit);
  for (int index : driven)
    if (index >= 0 && index < static_cast<int>(is_lip_.size()) && is_lip_[index])
      perturb(index, o.lip_gain, o.lip_misfit);
  return out;
}

Eigen::MatrixXd TrackingError::smooth_draw(uint64_t seed, int key, int components) const {
  const Mesh& neutral = head_.model.neutral;
  const FaceFrame& frame = head_.frame;
  const int n = head_.model.num_vertices();
  struct Bump {
    Eigen::Vector3d centre;
    Eigen::VectorXd amplitude;
  };
  std::vector<Bump> bumps(options_.offset_bumps);
  for (int b = 0; b < options_.offset_bumps; ++b) {
    for (int k = 0; k < 3; ++k)
      bumps[b].centre[k] = box_min_[k] + uniform(seed, key, b, k) * (box_max_[k] - box_min_[k]);
    bumps[b].amplitude.resize(components);
    for (int k = 0; k < components; ++k) bumps[b].amplitude[k] = gaussian(seed, key, b, 3 + k);
  }
  const double inv_two_sigma2 = 1.0 / (2 * options_.offset_scale * options_.offset_scale);
  const auto field = [&](const Eigen::Vector3d& p) {
    Eigen::VectorXd value = Eigen::VectorXd::Zero(components);
    for (const Bump& b : bumps) value += b.amplitude * std::exp(-(p - b.centre).squaredNorm() * inv_two_sigma2);
    return value;
  };
  const Eigen::VectorXd eye[3] = {Eigen::VectorXd::Zero(components), field(frame.to_face(frame.eye_left)),
                                  field(frame.to_face(frame.eye_right))};
  Eigen::MatrixXd d(n, components);
  for (int v = 0; v < n; ++v) {
    const int e = vertex_eye_[v];
    d.row(v) = (e ? eye[e] : field(frame.to_face(neutral.positions.row(v).cast<double>().transpose()))).transpose();
  }
  const double rms = skin_rms_of_rows(d);
  if (rms > 0) d /= rms;
  return d;
}

Eigen::MatrixXd TrackingError::offset_draw(uint64_t take_seed, int key) const {
  // Face-frame axes to head space (a rotation: the RMS stays 1).
  return smooth_draw(take_seed, key, 3) * head_.frame.axes.transpose();
}

Vertices TrackingError::offset(const std::string& take, int frame) const {
  const int n = head_.model.num_vertices();
  if (options_.offset_m == 0) return Vertices::Zero(n, 3);
  int key = 0;
  double weight = 0;
  keys(frame, key, weight);
  const uint64_t take_seed = hash_of(seed_, kOffsetSalt, hash_string(take.c_str()));
  Eigen::MatrixXd d = offset_draw(take_seed, key);
  if (weight > 0) d = (1 - weight) * d + weight * offset_draw(take_seed, key + 1);
  const double rms = skin_rms_of_rows(d);
  if (rms > 0) d *= options_.offset_m / rms;
  return d.cast<float>();
}

Vertices TrackingError::shape_error(const std::vector<float>& expression) const {
  const BlendshapeModel& model = head_.model;
  Eigen::MatrixXd error = Eigen::MatrixXd::Zero(model.num_vertices(), 3);
  for (size_t e = 0; e < shape_gains_.size() && e < expression.size(); ++e)
    if (expression[e] != 0)
      error += (options_.shape_misfit * expression[e]) * shape_gains_[e].asDiagonal() *
               model.expression_deltas[e].cast<double>();
  return error.cast<float>();
}

double TrackingError::skin_rms_of_rows(const Eigen::MatrixXd& rows) const {
  double sum2 = 0;
  int skin = 0;
  for (int v = 0; v < rows.rows(); ++v)
    if (!vertex_eye_[v]) sum2 += rows.row(v).squaredNorm(), ++skin;
  return skin ? std::sqrt(sum2 / skin) : 0.0;
}

double TrackingError::skin_rms(const Vertices& displacement) const {
  return skin_rms_of_rows(displacement.cast<double>());
}

double TrackingError::skin_max(const Vertices& displacement) const {
  double largest = 0;
  for (int v = 0; v < displacement.rows(); ++v)
    if (!vertex_eye_[v]) largest = std::max(largest, displacement.row(v).cast<double>().norm());
  return largest;
}

RigidTransform interpolate_pose(const RigidTransform& a, const RigidTransform& b, double weight) {
  if (weight == 0) return a;
  const Eigen::Quaterniond qa(a.R), qb(b.R);
  return {qa.slerp(weight, qb).toRotationMatrix(), (1 - weight) * a.t + weight * b.t};
}

}  // namespace tega::synth
