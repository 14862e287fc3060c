#include "tega/tracking/tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "eyelids.h"
#include "frame_targets.h"
#include "rigid_alignment.h"
#include "tega/core/error.h"

namespace tega::tracking {
namespace {

constexpr double kDegree = M_PI / 180;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Vertices with_shapes(Vertices base, const std::vector<Vertices>& shapes, const std::vector<double>& coefficients) {
  for (size_t k = 0; k < std::min(shapes.size(), coefficients.size()); ++k)
    if (coefficients[k] != 0) base += static_cast<float>(coefficients[k]) * shapes[k];
  return base;
}

// The ICP bound of iteration `it` of `count`: from max_distance_m down to final_distance_m.
double distance_bound(const SurfaceTermOptions& o, int it, int count) {
  if (count <= 1) return o.final_distance_m;
  return o.max_distance_m + (o.final_distance_m - o.max_distance_m) * double(it) / double(count - 1);
}

CorrectionProblem correction_problem(const std::vector<int>& vertices, const Options& options,
                                     const std::vector<std::pair<int, int>>& edges, const std::vector<Camera>& cameras) {
  const CorrectionOptions& o = options.corrections;
  CorrectionProblem p;
  p.vertices = &vertices;
  p.edges = &edges;
  p.smoothness = {o.smoothness_sigma_m, o.weight, 0};
  // The magnitude and temporal priors share the coefficient priors' weight.
  p.magnitude = {o.magnitude_sigma_m, options.coefficients.weight, 0};
  p.temporal = {o.temporal_sigma_m, options.coefficients.weight, 0};
  p.cameras = &cameras;
  p.iterations = o.solver_iterations;
  p.threads = options.threads;
  return p;
}

// How much of each open eye the identity frames show as skin, averaged.
std::map<std::string, double> open_eyes_covered(const HeadModel& model, const SubjectIdentity& subject,
                                                const std::vector<FrameObservation>& frames,
                                                const std::vector<RigidTransform>& poses,
                                                const std::vector<Camera>& cameras, const Options& options) {
  const ModelEyes eyes = find_model_eyes(model, options.eyelids);
  std::map<std::string, std::pair<double, int>> sums;
  for (size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].images.empty()) continue;
    HeadState open;
    open.head_to_world = poses[f];
    open.expression.assign(model.shapes.expression_deltas.size(), 0.0);
    for (const auto& eye : observe_eyelids(eyes, model, subject.neutral, open, frames[f].images, cameras, {},
                                           options.eyelids)) {
      auto& [sum, count] = sums[model.shapes.expression_names[size_t(eye.blink)]];
      sum += eye.seen_covered;
      ++count;
    }
  }
  std::map<std::string, double> covered;
  for (const auto& [name, sum] : sums) covered[name] = sum.first / sum.second;
  return covered;
}

}  // namespace

Vertices pose_vertices(const HeadModel& model, const SubjectIdentity& subject, const HeadState& state) {
  Vertices head = with_shapes(subject.neutral, model.shapes.expression_deltas, state.expression);
  if (state.corrections.rows() == head.rows()) head += state.corrections;
  return posed(head, state.head_to_world);
}

SubjectIdentity fit_identity(const HeadModel& model, const std::vector<FrameObservation>& frames,
                             const std::vector<Camera>& cameras, const Options& options,
                             const landmarks::LandmarkDetector* landmarks) {
  if (frames.empty()) throw Error("fitting the identity needs at least one frame");
  const Vertices& mean = model.shapes.neutral.positions;
  std::vector<std::unique_ptr<SurfaceQuery>> scans;
  std::vector<RigidTransform> poses;
  for (const auto& frame : frames) {
    scans.push_back(std::make_unique<SurfaceQuery>(*frame.scan));
    poses.push_back(initial_pose(model, mean, frame, cameras, options, landmarks));
  }
  const size_t F = frames.size();
  SubjectIdentity subject;
  subject.coefficients.assign(model.shapes.identity_deltas.size(), 0.0);
  const auto frame_targets = [&](const Vertices& head, double bound, const std::vector<int>& vertices) {
    std::vector<FrameTargets> targets(F);
    for (size_t f = 0; f < F; ++f) {
      const PosedModel p = posed_model(model, posed(head, poses[f]));
      targets[f].surface = surface_targets(p, vertices, *scans[f], bound, options.surface);
      if (landmarks)
        targets[f].images.push_back(
            landmark_targets(model, p, frames[f], cameras, *scans[f], *landmarks, options.landmarks));
    }
    return targets;
  };

  const int iterations = std::max(2, options.icp_iterations);
  for (int it = 0; it < iterations; ++it) {
    const Vertices head = with_shapes(mean, model.shapes.identity_deltas, subject.coefficients);
    CoefficientProblem p;
    p.base = &mean;
    p.basis = &model.shapes.identity_deltas;
    p.prior_sigma = options.coefficients.identity_sigma;
    p.prior_scale = {1, options.coefficients.weight, 0};
    p.cameras = &cameras;
    p.frames = frame_targets(head, distance_bound(options.surface, it, iterations), model.fit_vertices);
    p.iterations = 3 * options.coefficients.solver_iterations;  // once per subject
    p.threads = options.threads;
    fit_coefficients(p, poses, subject.coefficients);
  }
  subject.neutral = with_shapes(mean, model.shapes.identity_deltas, subject.coefficients);

  if (options.corrections.enabled) {
    const auto edges = edges_between(model.shapes.neutral.faces, model.skin_vertices);
    Vertices detail = Vertices::Zero(subject.neutral.rows(), 3);
    for (int it = 0; it < options.corrections.iterations + 1; ++it) {
      CorrectionProblem p = correction_problem(model.skin_vertices, options, edges, cameras);
      p.base = &subject.neutral;
      p.poses = poses;
      p.frames = frame_targets(subject.neutral + detail, options.surface.final_distance_m, model.fit_vertices);
      fit_corrections(p, detail);
    }
    // The detail is the subject's shape, not a turn of the head: what of it
    // is rigid goes, so that head space stays the model's.
    std::vector<Eigen::Vector3d> detailed, shaped;
    for (int v : model.skin_vertices) {
      detailed.push_back((subject.neutral.row(v) + detail.row(v)).cast<double>().transpose());
      shaped.push_back(subject.neutral.row(v).cast<double>().transpose());
    }
    const RigidTransform rigid_part = align(detailed, shaped);
    subject.neutral = posed(subject.neutral + detail, rigid_part);
    for (auto& pose : poses) pose = pose * rigid_part.inverse();  // the same world vertices
  }
  if (options.eyelids.enabled)
    subject.open_eyes_covered = open_eyes_covered(model, subject, frames, poses, cameras, options);
  return subject;
}

struct TakeTracker::Previous {
  HeadState state;
  PosedModel posed;
  std::unique_ptr<SurfaceQuery> scan;  // null: no flow to the next frame
  std::vector<Image8> images;
};

TakeTracker::TakeTracker(const HeadModel& model, const SubjectIdentity& subject, std::vector<Camera> cameras,
                         const Options& options, const landmarks::LandmarkDetector* landmarks)
    : model_(model),
      subject_(subject),
      cameras_(std::move(cameras)),
      options_(options),
      landmarks_(landmarks),
      fit_edges_(edges_between(model.shapes.neutral.faces, model.fit_vertices)) {
  if (options.eyelids.enabled) eyes_ = std::make_unique<ModelEyes>(find_model_eyes(model, options.eyelids));
}

TakeTracker::~TakeTracker() = default;

FrameFit TakeTracker::fit(const FrameObservation& frame, const Previous* previous) const {
  if (!frame.scan) throw Error("a frame to track needs its scan");
  const SurfaceQuery scan(*frame.scan);
  const Options& o = options_;
  const size_t E = model_.shapes.expression_deltas.size();

  FrameFit result;
  HeadState& state = result.state;
  if (previous) {
    state = previous->state;
  } else {
    state.head_to_world = initial_pose(model_, subject_.neutral, frame, cameras_, o, landmarks_);
    state.expression.assign(E, 0.0);
    state.corrections = Vertices::Zero(subject_.neutral.rows(), 3);
  }
  const Vertices base = subject_.neutral + state.corrections;

  auto start = std::chrono::steady_clock::now();
  std::vector<Term<ImageTarget>> image_terms;
  const bool has_images = !frame.images.empty();
  Term<ImageTarget> flow, landmarks;
  if (o.flow.enabled && has_images && previous && previous->scan)
    flow = flow_targets(model_, previous->posed, *previous->scan, previous->images, frame.images, cameras_, o.flow);
  if (landmarks_ && has_images)
    landmarks = landmark_targets(model_, posed_model(model_, pose_vertices(model_, subject_, state)), frame, cameras_,
                                 scan, *landmarks_, o.landmarks);
  if (!flow.targets.empty()) image_terms.push_back(flow);
  if (!landmarks.targets.empty()) image_terms.push_back(landmarks);
  result.timings.image_terms_s = seconds_since(start);
  start = std::chrono::steady_clock::now();

  // Coefficient priors: towards neutral, and towards the previous frame's
  // values when there is one (the product of the two Gaussians).
  const CoefficientOptions& co = o.coefficients;
  std::vector<double> prior_mean(E, 0.0);
  double prior_sigma = co.expression_sigma;
  if (previous) {
    const double a = 1 / (co.expression_sigma * co.expression_sigma);
    const double b = 1 / (co.expression_temporal_sigma * co.expression_temporal_sigma);
    for (size_t j = 0; j < E; ++j) prior_mean[j] = b * previous->state.expression[j] / (a + b);
    prior_sigma = 1 / std::sqrt(a + b);
  }
  std::vector<RigidTransform> poses = {state.head_to_world};
  const std::vector<int> coefficient_vertices = model_.fit_vertices_every(o.surface.coefficient_vertex_step);
  Term<CoefficientRange> blinks;
  blinks.scale = {o.eyelids.sigma, o.eyelids.weight, 0};
  for (int it = 0; it < o.icp_iterations; ++it) {
    const PosedModel now = posed_model(model_, pose_vertices(model_, subject_, state));
    // The first iteration fixes the pose on what no expression moves.
    const bool pose_only = it == 0;
    // The eyelids are observed once the head is in place and the rest of
    // the face has been fitted (a smile's cheeks narrow the eyes too).
    if (it >= 2 && eyes_ && has_images) {
      const auto started = std::chrono::steady_clock::now();
      blinks.targets.clear();
      const Vertices head = with_shapes(base, model_.shapes.expression_deltas, state.expression);
      for (const auto& eye : observe_eyelids(*eyes_, model_, head, state, frame.images, cameras_,
                                             subject_.open_eyes_covered, o.eyelids)) {
        blinks.targets.push_back({eye.blink, eye.low, eye.high});
        result.residuals.eyelids_covered[model_.shapes.expression_names[size_t(eye.blink)]] = eye.covered;
      }
      result.timings.image_terms_s += seconds_since(started);
    }
    CoefficientProblem p;
    p.base = &base;
    p.basis = &model_.shapes.expression_deltas;
    p.lower.assign(E, 0.0);
    p.upper.assign(E, 1.0);
    p.prior_mean = prior_mean;
    p.prior_sigma = prior_sigma;
    p.prior_scale = {1, co.weight, 0};
    p.ranges = blinks;
    p.cameras = &cameras_;
    const double bound = distance_bound(o.surface, it, o.icp_iterations);
    p.frames.push_back({surface_targets(now, pose_only ? model_.pose_vertices : coefficient_vertices, scan, bound,
                                        o.surface),
                        pose_only ? std::vector<Term<ImageTarget>>{} : image_terms});
    if (previous) p.pose_priors.push_back(&previous->state.head_to_world);
    p.rotation_sigma_rad = co.rotation_temporal_sigma_deg * kDegree;
    p.translation_sigma_m = co.translation_temporal_sigma_m;
    p.iterations = co.solver_iterations;
    p.threads = o.threads;
    p.fit_coefficients = !pose_only;
    fit_coefficients(p, poses, state.expression);
    state.head_to_world = poses[0];
  }
  result.timings.coefficients_s = seconds_since(start);

  start = std::chrono::steady_clock::now();
  if (o.corrections.enabled) {
    const Vertices shaped = with_shapes(subject_.neutral, model_.shapes.expression_deltas, state.expression);
    for (int it = 0; it < std::max(1, o.corrections.iterations); ++it) {
      const PosedModel now = posed_model(model_, pose_vertices(model_, subject_, state));
      CorrectionProblem p = correction_problem(model_.fit_vertices, o, fit_edges_, cameras_);
      p.base = &shaped;
      p.previous = previous ? &previous->state.corrections : nullptr;
      p.poses = {state.head_to_world};
      p.frames.push_back(
          {surface_targets(now, model_.fit_vertices, scan, o.surface.final_distance_m, o.surface), image_terms});
      fit_corrections(p, state.corrections);
    }
  }

  result.timings.corrections_s = seconds_since(start);
  result.vertices = pose_vertices(model_, subject_, state);
  surface_residuals(posed_model(model_, result.vertices), model_, scan, o.surface, result.residuals);
  result.residuals.flow_rms_px = reprojection_rms(flow, result.vertices, cameras_);
  result.residuals.flow_count = int(flow.targets.size());
  result.residuals.landmark_rms_px = reprojection_rms(landmarks, result.vertices, cameras_);
  result.residuals.landmark_count = int(landmarks.targets.size());
  return result;
}

FrameFit TakeTracker::track(const FrameObservation& frame) {
  FrameFit warm = fit(frame, previous_.get());
  if (!previous_ || (!rejection(warm) && !moved_far(warm))) return warm;
  // A fast move or key poses far apart: ICP from the previous pose can
  // settle on a face turned about the skull, which a fit from scratch avoids.
  FrameFit fresh;
  try {
    fresh = fit(frame, nullptr);
  } catch (const Error&) {  // no head where a first pose would be sought
    return warm;
  }
  fresh.fitted_afresh = true;
  FrameFit& kept = fresh.residuals.surface_capped_mean_m < warm.residuals.surface_capped_mean_m ? fresh : warm;
  const FrameFit& other = &kept == &fresh ? warm : fresh;
  kept.timings.image_terms_s += other.timings.image_terms_s;
  kept.timings.coefficients_s += other.timings.coefficients_s;
  kept.timings.corrections_s += other.timings.corrections_s;
  return std::move(kept);
}

bool TakeTracker::moved_far(const FrameFit& fit) const {
  const RigidTransform& from = previous_->state.head_to_world;
  const RigidTransform& to = fit.state.head_to_world;
  const double turn = Eigen::AngleAxisd(to.R * from.R.transpose()).angle();
  const double shift = (to.t - from.t).norm();
  return turn > options_.fresh_start.rotation_deg * kDegree || shift > options_.fresh_start.translation_m;
}

std::optional<std::string> TakeTracker::rejection(const FrameFit& fit) const {
  const FrameResiduals& r = fit.residuals;
  char reason[160];
  if (r.inlier_fraction < options_.min_inlier_fraction) {
    std::snprintf(reason, sizeof reason, "only %.0f %% of the face lies within %.1f mm of the scan (minimum %.0f %%)",
                  100 * r.inlier_fraction, 1000 * options_.surface.final_distance_m,
                  100 * options_.min_inlier_fraction);
    return reason;
  }
  if (r.surface_median_m > options_.max_median_distance_m) {
    std::snprintf(reason, sizeof reason, "the face lies %.2f mm from the scan (median; at most %.2f mm)",
                  1000 * r.surface_median_m, 1000 * options_.max_median_distance_m);
    return reason;
  }
  return std::nullopt;
}

void TakeTracker::accept(const FrameFit& fit, const FrameObservation& frame) {
  previous_ = std::make_unique<Previous>();
  previous_->state = fit.state;
  previous_->posed = posed_model(model_, fit.vertices);
  if (!frame.images.empty() && frame.scan) {
    previous_->scan = std::make_unique<SurfaceQuery>(*frame.scan);
    previous_->images = frame.images;
  }
}

void TakeTracker::resume_from(const HeadState& state) {
  previous_ = std::make_unique<Previous>();
  previous_->state = state;
  previous_->posed = posed_model(model_, pose_vertices(model_, subject_, state));
}

void TakeTracker::break_sequence() {
  if (!previous_) return;
  previous_->scan.reset();
  previous_->images.clear();
}

}  // namespace tega::tracking
