// Where the head is before any frame says so: landmarks triangulated across
// views where a detector finds the face, else the scan's front and the rig's
// orientation, turned a few ways; then rigid ICP on the parts of the face no
// expression moves.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include "frame_targets.h"
#include "rigid_alignment.h"
#include "tega/core/error.h"
#include "tega/core/log.h"

namespace tega::tracking {
namespace {

constexpr int kRigidIcpIterations = 8;
constexpr double kRigidIcpStartDistanceM = 0.04;
constexpr double kFrontFacingCosine = 0.3;
constexpr double kStartYawsDeg[] = {0, -15, 15, -30, 30};
constexpr size_t kMinCorrespondences = 50;

// The point closest to all rays (camera centre, unit direction) in the least-squares sense.
Eigen::Vector3d closest_to_rays(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& rays) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& [origin, direction] : rays) {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - direction * direction.transpose();
    A += P;
    b += P * origin;
  }
  return A.ldlt().solve(b);
}

std::optional<RigidTransform> pose_from_landmarks(const HeadModel& model, const Vertices& neutral,
                                                  const FrameObservation& frame, const std::vector<Camera>& cameras,
                                                  const landmarks::LandmarkDetector& detector, int min_views) {
  if (model.landmark_vertices.empty()) return std::nullopt;
  std::vector<std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>> rays(landmarks::kLandmarkCount);
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (c >= frame.images.size() || frame.images[c].pixels.empty()) continue;
    const auto found = detector.detect(frame.images[c], std::nullopt);
    if (!found) continue;
    for (int l = 0; l < landmarks::kLandmarkCount; ++l)
      rays[size_t(l)].emplace_back(cameras[c].center(), cameras[c].ray_direction((*found)[size_t(l)]));
  }
  std::vector<Eigen::Vector3d> head_points, world_points;
  for (int l = 17; l < landmarks::kLandmarkCount; ++l) {  // the jaw line is a silhouette, not a point
    if (int(rays[size_t(l)].size()) < std::max(2, min_views)) continue;
    head_points.push_back(neutral.row(model.landmark_vertices[size_t(l)]).cast<double>().transpose());
    world_points.push_back(closest_to_rays(rays[size_t(l)]));
  }
  if (head_points.size() < 6) return std::nullopt;
  return align(head_points, world_points);
}

// The face looks towards the cameras, upright as they are on average; its
// front lies on the part of the scan facing them.
RigidTransform pose_from_rig(const HeadModel& model, const Vertices& neutral, const Mesh& scan,
                             const std::vector<Camera>& cameras) {
  Eigen::Vector3d eyes = Eigen::Vector3d::Zero(), up = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) {
    eyes += c.center();
    up -= c.world_to_camera.R.row(1).transpose();  // image y points down
  }
  eyes /= double(cameras.size());
  Eigen::Vector3d scan_centre = Eigen::Vector3d::Zero();
  for (int v = 0; v < scan.num_vertices(); ++v) scan_centre += scan.positions.row(v).cast<double>().transpose();
  scan_centre /= double(std::max(1, scan.num_vertices()));
  const Eigen::Vector3d forward = (eyes - scan_centre).normalized();
  up = (up - up.dot(forward) * forward).normalized();
  RigidTransform pose;
  pose.R.col(0) = up.cross(forward);
  pose.R.col(1) = up;
  pose.R.col(2) = forward;

  const Vertices normals = scan.vertex_normals();
  Eigen::Vector3d front = Eigen::Vector3d::Zero();
  int count = 0;
  for (int v = 0; v < scan.num_vertices(); ++v)
    if (normals.row(v).cast<double>().dot(forward) > kFrontFacingCosine)
      front += scan.positions.row(v).cast<double>().transpose(), ++count;
  if (count == 0) throw Error("the scan has no surface facing the cameras");
  Eigen::Vector3d face = Eigen::Vector3d::Zero();
  for (int v : model.fit_vertices) face += neutral.row(v).cast<double>().transpose();
  face /= double(model.fit_vertices.size());
  pose.t = front / count - pose.R * face;
  return pose;
}

struct RigidFit {
  RigidTransform pose;
  size_t supported = 0;  // rigid-part vertices with a scan point within the final bound
};

// Rigid ICP of the neutral head's rigid part, the bound shrinking from a few
// centimetres to the surface term's first bound. `supported` is 0 where the
// scan met too little of it to fit (a start turned too far, or no head there).
RigidFit rigid_icp(const HeadModel& model, const Vertices& neutral, const SurfaceQuery& scan, const RigidTransform& start,
                   const Options& options) {
  std::vector<RigidTransform> poses = {start};
  std::vector<double> none;
  size_t supported = 0;
  for (int it = 0; it < kRigidIcpIterations; ++it) {
    const Vertices world = transformed(poses[0], neutral);
    const double bound = kRigidIcpStartDistanceM + (options.surface.max_distance_m - kRigidIcpStartDistanceM) *
                                                       double(it) / (kRigidIcpIterations - 1);
    CoefficientProblem problem;
    problem.base = &neutral;
    problem.fit_coefficients = false;
    problem.frames.push_back({surface_targets(posed_model(model, world), model.pose_vertices, scan, bound,
                                              options.surface),
                              {}});
    problem.frames[0].surface.scale.robust_scale = options.surface.robust_scale;
    problem.iterations = 3 * options.coefficients.solver_iterations;  // once per take
    problem.threads = options.threads;
    supported = problem.frames[0].surface.targets.size();
    if (supported < kMinCorrespondences) return {start, 0};
    fit_coefficients(problem, poses, none);
  }
  return {poses[0], supported};
}

Error no_head_near() {
  return Error("the scan does not meet the head model near where the head should be (fewer than " +
               std::to_string(kMinCorrespondences) + " correspondences)");
}

}  // namespace

RigidTransform initial_pose(const HeadModel& model, const Vertices& neutral, const FrameObservation& frame,
                            const std::vector<Camera>& cameras, const Options& options,
                            const landmarks::LandmarkDetector* landmarks) {
  const SurfaceQuery scan(*frame.scan);
  if (landmarks) {
    if (auto pose = pose_from_landmarks(model, neutral, frame, cameras, *landmarks, options.landmarks.min_views)) {
      const RigidFit fit = rigid_icp(model, neutral, scan, *pose, options);
      if (fit.supported == 0) throw no_head_near();
      return fit.pose;
    }
  }
  // The rig only says roughly where the face looks; a head turned away from
  // the rig's centre can pull ICP into a rolled, shifted fit of the brow and
  // cheeks. So start turned either way too, about the face's centre and the
  // rig's up axis, and keep the fit the most of the rigid part supports.
  const RigidTransform guess = pose_from_rig(model, neutral, *frame.scan, cameras);
  Eigen::Vector3d face = Eigen::Vector3d::Zero();
  for (int v : model.fit_vertices) face += neutral.row(v).cast<double>().transpose();
  const Eigen::Vector3d centre = guess.apply(face / double(model.fit_vertices.size()));
  const Eigen::Vector3d up = guess.R.col(1);
  RigidFit best;
  for (const double yaw_deg : kStartYawsDeg) {
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(yaw_deg * M_PI / 180, up).toRotationMatrix();
    const RigidTransform start{turn * guess.R, centre + turn * (guess.t - centre)};
    RigidFit fit = rigid_icp(model, neutral, scan, start, options);
    if (fit.supported > best.supported) best = std::move(fit);
  }
  if (best.supported == 0) throw no_head_near();
  return best.pose;
}

}  // namespace tega::tracking
