#pragma once
// The least-squares problems of tracking, on Ceres. A posed model vertex is
//   X_v = R (base_v + sum_k s_k basis_k[v] + c_v) + t,
// with (R, t) the head pose, s the coefficients of a shape basis (identity
// shapes when fitting a subject, expression shapes when tracking) and c the
// per-vertex corrections. Two solves alternate with correspondence updates:
// fit_coefficients (pose and coefficients, corrections fixed) and
// fit_corrections (corrections, pose and coefficients fixed).

#include <Eigen/Core>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega::tracking {

// A model vertex should lie on the plane through `point` with `normal`.
struct SurfaceTarget {
  int vertex = 0;
  Eigen::Vector3d point, normal;
};

// A model vertex should project to `pixel` in `camera`.
struct ImageTarget {
  int vertex = 0;
  int camera = 0;
  Eigen::Vector2d pixel;
};

// A group of residuals and how it counts: each residual divided by sigma,
// the group scaled by sqrt(weight / count), a Cauchy loss at robust_scale
// sigmas (0: plain least squares).
struct TermScale {
  double sigma = 1, weight = 1, robust_scale = 0;
};

template <class Target>
struct Term {
  std::vector<Target> targets;
  TermScale scale;
};

// What one frame contributes to a fit.
struct FrameTargets {
  Term<SurfaceTarget> surface;
  std::vector<Term<ImageTarget>> images;  // flow, landmarks, ...
};

// A coefficient should lie in [low, high]; outside, it costs its distance
// to the range over the term's sigma.
struct CoefficientRange {
  int coefficient = 0;
  double low = 0, high = 1;
};

struct CoefficientProblem {
  const Vertices* base = nullptr;           // V x 3, head space, corrections included
  const std::vector<Vertices>* basis = nullptr;  // K shapes, V x 3 each
  std::vector<double> lower, upper;         // bounds on the coefficients (empty: none)
  std::vector<double> prior_mean;           // coefficients are drawn towards these ...
  double prior_sigma = 1;                   // ... with this spread
  TermScale prior_scale;                    // (the prior's share of the energy; sigma unused)
  Term<CoefficientRange> ranges;            // e.g. the blinks the photos show
  const std::vector<Camera>* cameras = nullptr;
  // Per frame: its targets, and a prior on its pose (previous frame's) when set.
  std::vector<FrameTargets> frames;
  std::vector<const RigidTransform*> pose_priors;  // per frame, may be null
  double rotation_sigma_rad = 0.05, translation_sigma_m = 0.005;
  int iterations = 15;
  int threads = 1;
  bool fit_coefficients = true;  // false: the pose alone
};

// Solves for one pose per frame and shared coefficients, starting from the
// values passed in.
void fit_coefficients(const CoefficientProblem& problem, std::vector<RigidTransform>& poses,
                      std::vector<double>& coefficients);

struct CorrectionProblem {
  const Vertices* base = nullptr;            // V x 3, head space, corrections excluded
  const std::vector<int>* vertices = nullptr;  // the vertices that take corrections
  const std::vector<std::pair<int, int>>* edges = nullptr;  // between those vertices
  const Vertices* previous = nullptr;        // corrections to stay near (may be null)
  TermScale smoothness, magnitude, temporal;  // sigma in metres
  const std::vector<Camera>* cameras = nullptr;
  std::vector<RigidTransform> poses;         // per frame, fixed
  std::vector<FrameTargets> frames;
  int iterations = 5;
  int threads = 1;
};

// Per-vertex corrections (V x 3, head space; zero outside problem.vertices),
// starting from and written into `corrections`.
void fit_corrections(const CorrectionProblem& problem, Vertices& corrections);

// The edges of `faces` whose both ends are in `vertices`, each once.
std::vector<std::pair<int, int>> edges_between(const Triangles& faces, const std::vector<int>& vertices);

}  // namespace tega::tracking
