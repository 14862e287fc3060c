#include "model_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <set>

#include "tega/core/thread_pool.h"

namespace tega::tracking {
namespace {

// What a residual asks of a posed vertex X: a distance along a normal, or a
// projection into a camera. Returns the residual (divided by sigma) and its
// derivative by X.
struct Measurement {
  enum class Kind { plane, pixel } kind = Kind::plane;
  Eigen::Vector3d point, normal;  // plane
  const Camera* camera = nullptr;  // pixel
  Eigen::Vector2d pixel;
  double inverse_sigma = 1;

  int size() const { return kind == Kind::plane ? 1 : 2; }

  // False when X is behind the camera (the residual cannot be evaluated).
  bool evaluate(const Eigen::Vector3d& X, double* residual, Eigen::Matrix<double, 2, 3>* by_X) const {
    if (kind == Kind::plane) {
      residual[0] = inverse_sigma * normal.dot(X - point);
      if (by_X) by_X->row(0) = inverse_sigma * normal.transpose();
      return true;
    }
    const auto projected = camera->project(X);
    if (!projected) return false;
    const Eigen::Vector2d r = inverse_sigma * (*projected - pixel);
    residual[0] = r.x();
    residual[1] = r.y();
    if (by_X) *by_X = inverse_sigma * camera->projection_jacobian(X);
    return true;
  }
};

Measurement plane_of(const SurfaceTarget& t, double sigma) {
  Measurement m;
  m.point = t.point;
  m.normal = t.normal;
  m.inverse_sigma = 1 / sigma;
  return m;
}

Measurement pixel_of(const ImageTarget& t, const std::vector<Camera>& cameras, double sigma) {
  Measurement m;
  m.kind = Measurement::Kind::pixel;
  m.camera = &cameras.at(size_t(t.camera));
  m.pixel = t.pixel;
  m.inverse_sigma = 1 / sigma;
  return m;
}

// d(R x)/d(q) for a unit quaternion q = (v, w) stored as Eigen does (x, y,
// z, w), from R x = (w^2 - v.v) x + 2 (v.x) v + 2 w (v cross x).
Eigen::Matrix<double, 3, 4> rotated_point_by_quaternion(const Eigen::Quaterniond& q, const Eigen::Vector3d& x) {
  const Eigen::Vector3d v = q.vec();
  const double w = q.w();
  Eigen::Matrix3d cross_x;
  cross_x << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
  Eigen::Matrix<double, 3, 4> J;
  J.leftCols<3>() = -2 * x * v.transpose() + 2 * v * x.transpose() + 2 * v.dot(x) * Eigen::Matrix3d::Identity() -
                    2 * w * cross_x;
  J.col(3) = 2 * w * x + 2 * v.cross(x);
  return J;
}

// X = R (x0 + B s) + t; parameter blocks: quaternion (4), translation (3),
// and the coefficients s (K) when K > 0.
class ModelPointCost final : public ceres::CostFunction {
 public:
  ModelPointCost(Eigen::Vector3d x0, Eigen::Matrix<double, 3, Eigen::Dynamic> basis, Measurement measurement)
      : x0_(std::move(x0)), basis_(std::move(basis)), measurement_(std::move(measurement)) {
    set_num_residuals(measurement_.size());
    mutable_parameter_block_sizes()->push_back(4);
    mutable_parameter_block_sizes()->push_back(3);
    if (basis_.cols() > 0) mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(basis_.cols()));
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
    const Eigen::Quaterniond unit = q.normalized();
    const Eigen::Matrix3d R = unit.toRotationMatrix();
    const Eigen::Vector3d t(parameters[1]);
    Eigen::Vector3d x = x0_;
    const long K = basis_.cols();
    if (K > 0) x += basis_ * Eigen::Map<const Eigen::VectorXd>(parameters[2], K);
    const Eigen::Vector3d X = R * x + t;
    Eigen::Matrix<double, 2, 3> by_X;
    const int n = measurement_.size();
    if (!measurement_.evaluate(X, residuals, jacobians ? &by_X : nullptr)) return false;
    if (!jacobians) return true;
    const auto G = by_X.topRows(n);
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>> J(jacobians[0], n, 4);
      J = G * rotated_point_by_quaternion(unit, x);
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> J(jacobians[1], n, 3);
      J = G;
    }
    if (K > 0 && jacobians[2]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jacobians[2], n, K);
      J = G * R * basis_;
    }
    return true;
  }

 private:
  Eigen::Vector3d x0_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> basis_;
  Measurement measurement_;
};

// X = R (x0 + c) + t with the pose fixed; one parameter block, c (3).
class CorrectedPointCost final : public ceres::SizedCostFunction<ceres::DYNAMIC, 3> {
 public:
  CorrectedPointCost(Eigen::Vector3d x0, const RigidTransform& pose, Measurement measurement)
      : x0_(std::move(x0)), pose_(pose), measurement_(std::move(measurement)) {
    set_num_residuals(measurement_.size());
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Vector3d X = pose_.apply(x0_ + Eigen::Vector3d(parameters[0]));
    Eigen::Matrix<double, 2, 3> by_X;
    if (!measurement_.evaluate(X, residuals, jacobians ? &by_X : nullptr)) return false;
    if (jacobians && jacobians[0]) {
      const int n = measurement_.size();
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> J(jacobians[0], n, 3);
      J = by_X.topRows(n) * pose_.R;
    }
    return true;
  }

 private:
  Eigen::Vector3d x0_;
  RigidTransform pose_;
  Measurement measurement_;
};

// (x - target) / sigma over a block of any size.
class DeviationCost final : public ceres::CostFunction {
 public:
  DeviationCost(Eigen::VectorXd target, double sigma) : target_(std::move(target)), inverse_sigma_(1 / sigma) {
    set_num_residuals(static_cast<int>(target_.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(target_.size()));
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const long n = target_.size();
    Eigen::Map<Eigen::VectorXd>(residuals, n) =
        inverse_sigma_ * (Eigen::Map<const Eigen::VectorXd>(parameters[0], n) - target_);
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::MatrixXd>(jacobians[0], n, n) = inverse_sigma_ * Eigen::MatrixXd::Identity(n, n);
    }
    return true;
  }

 private:
  Eigen::VectorXd target_;
  double inverse_sigma_;
};

// A coefficient's distance outside its range, over sigma.
class RangeCost : public ceres::CostFunction {
 public:
  RangeCost(long count, const CoefficientRange& range, double sigma)
      : count_(count), k_(range.coefficient), low_(range.low), high_(range.high), inverse_sigma_(1 / sigma) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(static_cast<int32_t>(count));
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double s = parameters[0][k_];
    const double slope = s < low_ ? -1 : s > high_ ? 1 : 0;
    residuals[0] = inverse_sigma_ * slope * (s - (s < low_ ? low_ : high_));
    if (jacobians && jacobians[0]) {
      std::fill(jacobians[0], jacobians[0] + count_, 0.0);
      jacobians[0][k_] = inverse_sigma_ * slope;
    }
    return true;
  }

 private:
  long count_;
  int k_;
  double low_, high_, inverse_sigma_;
};

// (a - b) / sigma for two 3-vectors: the membrane between neighbouring corrections.
struct EdgeDifference {
  double inverse_sigma;
  template <class T>
  bool operator()(const T* a, const T* b, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = T(inverse_sigma) * (a[k] - b[k]);
    return true;
  }
};

// A pose's rotation and translation away from a prior pose.
struct PoseDeviation {
  Eigen::Quaterniond prior_inverse;
  Eigen::Vector3d prior_t;
  double inverse_rotation_sigma, inverse_translation_sigma;
  template <class T>
  bool operator()(const T* q, const T* t, T* residual) const {
    const Eigen::Quaternion<T> rotation(q[3], q[0], q[1], q[2]);
    Eigen::Quaternion<T> delta = prior_inverse.cast<T>() * rotation.normalized();
    if (delta.w() < T(0)) delta.coeffs() = -delta.coeffs();
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(2 * inverse_rotation_sigma) * delta.vec()[k];
      residual[3 + k] = T(inverse_translation_sigma) * (t[k] - T(prior_t[k]));
    }
    return true;
  }
};

// A term's residuals count sqrt(weight / count) each, with a Cauchy loss when asked.
ceres::LossFunction* loss_of(const TermScale& scale, size_t count) {
  if (count == 0) return nullptr;
  ceres::LossFunction* robust = scale.robust_scale > 0 ? new ceres::CauchyLoss(scale.robust_scale) : nullptr;
  return new ceres::ScaledLoss(robust, scale.weight / double(count), ceres::TAKE_OWNERSHIP);
}

ceres::Solver::Options solver_options(int iterations, int threads, ceres::LinearSolverType solver) {
  ceres::Solver::Options o;
  o.max_num_iterations = iterations;
  o.num_threads = threads > 0 ? threads : default_thread_count();
  o.linear_solver_type = solver;
  o.logging_type = ceres::SILENT;
  o.function_tolerance = 1e-7;
  o.parameter_tolerance = 1e-9;
  return o;
}

struct PoseBlock {
  Eigen::Vector4d q;  // x, y, z, w
  Eigen::Vector3d t;
};

}  // namespace

void fit_coefficients(const CoefficientProblem& p, std::vector<RigidTransform>& poses,
                      std::vector<double>& coefficients) {
  const Vertices& base = *p.base;
  const long K = p.fit_coefficients && p.basis ? static_cast<long>(p.basis->size()) : 0;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);

  std::vector<PoseBlock> blocks(poses.size());
  for (size_t f = 0; f < poses.size(); ++f) {
    blocks[f].q = Eigen::Quaterniond(poses[f].R).coeffs();
    blocks[f].t = poses[f].t;
    problem.AddParameterBlock(blocks[f].q.data(), 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(blocks[f].t.data(), 3);
  }
  std::vector<double> s(coefficients);
  // The coefficients outside the fit still shape the base.
  Vertices fixed_base = base;
  if (p.basis && !p.fit_coefficients)
    for (size_t k = 0; k < std::min(s.size(), p.basis->size()); ++k)
      fixed_base += static_cast<float>(s[k]) * (*p.basis)[k];

  const auto basis_rows = [&](int v) {
    Eigen::Matrix<double, 3, Eigen::Dynamic> B(3, K);
    for (long k = 0; k < K; ++k) B.col(k) = (*p.basis)[size_t(k)].row(v).cast<double>().transpose();
    return B;
  };
  const auto add_point = [&](size_t f, int v, Measurement m, ceres::LossFunction* loss) {
    auto* cost = new ModelPointCost(fixed_base.row(v).cast<double>().transpose(), basis_rows(v), std::move(m));
    if (K > 0)
      problem.AddResidualBlock(cost, loss, blocks[f].q.data(), blocks[f].t.data(), s.data());
    else
      problem.AddResidualBlock(cost, loss, blocks[f].q.data(), blocks[f].t.data());
  };
  for (size_t f = 0; f < p.frames.size(); ++f) {
    const FrameTargets& frame = p.frames[f];
    ceres::LossFunction* surface_loss = loss_of(frame.surface.scale, frame.surface.targets.size());
    for (const auto& target : frame.surface.targets)
      add_point(f, target.vertex, plane_of(target, frame.surface.scale.sigma), surface_loss);
    for (const auto& term : frame.images) {
      ceres::LossFunction* loss = loss_of(term.scale, term.targets.size());
      for (const auto& target : term.targets) add_point(f, target.vertex, pixel_of(target, *p.cameras, term.scale.sigma), loss);
    }
    if (f < p.pose_priors.size() && p.pose_priors[f]) {
      const RigidTransform& prior = *p.pose_priors[f];
      auto* cost = new ceres::AutoDiffCostFunction<PoseDeviation, 6, 4, 3>(new PoseDeviation{
          Eigen::Quaterniond(prior.R).conjugate(), prior.t, 1 / p.rotation_sigma_rad, 1 / p.translation_sigma_m});
      problem.AddResidualBlock(cost, loss_of(p.prior_scale, 1), blocks[f].q.data(), blocks[f].t.data());
    }
  }
  if (K > 0) {
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(K);
    for (long k = 0; k < std::min<long>(K, long(p.prior_mean.size())); ++k) mean[k] = p.prior_mean[size_t(k)];
    problem.AddResidualBlock(new DeviationCost(mean, p.prior_sigma), loss_of(p.prior_scale, 1), s.data());
    ceres::LossFunction* range_loss = loss_of(p.ranges.scale, p.ranges.targets.size());
    for (const auto& range : p.ranges.targets)
      if (range.coefficient >= 0 && range.coefficient < K)
        problem.AddResidualBlock(new RangeCost(K, range, p.ranges.scale.sigma), range_loss, s.data());
    for (long k = 0; k < K; ++k) {
      if (k < long(p.lower.size())) problem.SetParameterLowerBound(s.data(), int(k), p.lower[size_t(k)]);
      if (k < long(p.upper.size())) problem.SetParameterUpperBound(s.data(), int(k), p.upper[size_t(k)]);
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(p.iterations, p.threads, ceres::DENSE_NORMAL_CHOLESKY), &problem, &summary);
  for (size_t f = 0; f < poses.size(); ++f) {
    poses[f].R = Eigen::Quaterniond(blocks[f].q).normalized().toRotationMatrix();
    poses[f].t = blocks[f].t;
  }
  if (K > 0) coefficients = s;
}

void fit_corrections(const CorrectionProblem& p, Vertices& corrections) {
  const std::vector<int>& vertices = *p.vertices;
  std::vector<int> slot(size_t(p.base->rows()), -1);
  for (size_t i = 0; i < vertices.size(); ++i) slot[size_t(vertices[i])] = int(i);
  std::vector<Eigen::Vector3d> c(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) c[i] = corrections.row(vertices[i]).cast<double>().transpose();

  ceres::Problem problem;
  const auto add_point = [&](size_t f, int v, Measurement m, ceres::LossFunction* loss) {
    if (slot[size_t(v)] < 0) return;
    problem.AddResidualBlock(new CorrectedPointCost(p.base->row(v).cast<double>().transpose(), p.poses[f], std::move(m)),
                             loss, c[size_t(slot[size_t(v)])].data());
  };
  for (size_t f = 0; f < p.frames.size(); ++f) {
    const FrameTargets& frame = p.frames[f];
    ceres::LossFunction* surface_loss = loss_of(frame.surface.scale, frame.surface.targets.size());
    for (const auto& target : frame.surface.targets)
      add_point(f, target.vertex, plane_of(target, frame.surface.scale.sigma), surface_loss);
    for (const auto& term : frame.images) {
      ceres::LossFunction* loss = loss_of(term.scale, term.targets.size());
      for (const auto& target : term.targets) add_point(f, target.vertex, pixel_of(target, *p.cameras, term.scale.sigma), loss);
    }
  }
  ceres::LossFunction* smooth_loss = loss_of(p.smoothness, p.edges->size());
  for (const auto& [a, b] : *p.edges)
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<EdgeDifference, 3, 3, 3>(new EdgeDifference{1 / p.smoothness.sigma}),
        smooth_loss, c[size_t(slot[size_t(a)])].data(), c[size_t(slot[size_t(b)])].data());
  ceres::LossFunction* magnitude_loss = loss_of(p.magnitude, vertices.size());
  ceres::LossFunction* temporal_loss = p.previous ? loss_of(p.temporal, vertices.size()) : nullptr;
  for (size_t i = 0; i < vertices.size(); ++i) {
    problem.AddResidualBlock(new DeviationCost(Eigen::Vector3d::Zero(), p.magnitude.sigma), magnitude_loss, c[i].data());
    if (p.previous)
      problem.AddResidualBlock(
          new DeviationCost(p.previous->row(vertices[i]).cast<double>().transpose(), p.temporal.sigma), temporal_loss,
          c[i].data());
  }
  // Conjugate gradients on the normal equations: the corrections are smooth,
  // so a few dozen Jacobi-preconditioned steps reach the accuracy of a sparse
  // Cholesky factorisation in a fraction of its time (measured: docs/tracking.md).
  ceres::Solver::Options solver = solver_options(p.iterations, p.threads, ceres::CGNR);
  solver.preconditioner_type = ceres::JACOBI;
  solver.max_linear_solver_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  for (size_t i = 0; i < vertices.size(); ++i) corrections.row(vertices[i]) = c[i].cast<float>().transpose();
}

std::vector<std::pair<int, int>> edges_between(const Triangles& faces, const std::vector<int>& vertices) {
  std::vector<char> member;
  for (int v : vertices) {
    if (size_t(v) >= member.size()) member.resize(size_t(v) + 1, 0);
    member[size_t(v)] = 1;
  }
  const auto in = [&](int v) { return size_t(v) < member.size() && member[size_t(v)]; };
  std::set<std::pair<int, int>> edges;
  for (int f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = faces(f, k), b = faces(f, (k + 1) % 3);
      if (in(a) && in(b)) edges.insert({std::min(a, b), std::max(a, b)});
    }
  return {edges.begin(), edges.end()};
}

}  // namespace tega::tracking
