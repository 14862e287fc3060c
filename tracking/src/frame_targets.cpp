#include "frame_targets.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <tuple>

#include "tega/core/thread_pool.h"

namespace tega::tracking {
namespace {

constexpr int kFirstInnerLandmark = 17;
constexpr double kOcclusionMarginM = 0.003;
constexpr double kMinFacingCosine = 0.2;  // grazing views track poorly

std::vector<Eigen::Vector3d> rows_of(const Vertices& world, const std::vector<int>& vertices) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(vertices.size());
  for (int v : vertices) points.push_back(world.row(v).cast<double>().transpose());
  return points;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

// Cameras finish in any order; a fixed order keeps runs reproducible.
void sort_targets(Term<ImageTarget>& term) {
  std::sort(term.targets.begin(), term.targets.end(), [](const ImageTarget& a, const ImageTarget& b) {
    return std::tie(a.camera, a.vertex) < std::tie(b.camera, b.vertex);
  });
}

}  // namespace

TermScale scale_of(const ImageTermOptions& o) { return {o.sigma_px, o.weight, o.robust_scale}; }
TermScale scale_of(const SurfaceTermOptions& o) { return {o.sigma_m, o.weight, o.robust_scale}; }

PosedModel posed_model(const HeadModel& model, const Vertices& world) {
  Mesh mesh;
  mesh.positions = world;
  mesh.faces = model.shapes.neutral.faces;
  return {world, mesh.vertex_normals()};
}

Term<SurfaceTarget> surface_targets(const PosedModel& posed, const std::vector<int>& vertices, const SurfaceQuery& scan,
                                    double max_distance_m, const SurfaceTermOptions& options) {
  const std::vector<Eigen::Vector3d> points = rows_of(posed.world, vertices);
  const std::vector<ClosestPoint> closest = scan.closest(points);
  const double min_cosine = std::cos(options.max_normal_angle_deg * M_PI / 180);
  Term<SurfaceTarget> term;
  term.scale = scale_of(options);
  for (size_t i = 0; i < vertices.size(); ++i) {
    if ((closest[i].point - points[i]).norm() > max_distance_m) continue;
    const Eigen::Vector3d normal = posed.normals.row(vertices[i]).cast<double>().transpose();
    if (normal.dot(closest[i].normal) < min_cosine) continue;
    term.targets.push_back({vertices[i], closest[i].point, closest[i].normal});
  }
  return term;
}

void surface_residuals(const PosedModel& posed, const HeadModel& model, const SurfaceQuery& scan,
                       const SurfaceTermOptions& options, FrameResiduals& residuals) {
  const Term<SurfaceTarget> found = surface_targets(posed, model.fit_vertices, scan, options.final_distance_m, options);
  std::vector<double> distances;
  for (const auto& t : found.targets)
    distances.push_back((posed.world.row(t.vertex).cast<double>().transpose() - t.point).norm());
  residuals.inlier_fraction = double(distances.size()) / double(model.fit_vertices.size());
  residuals.surface_median_m = percentile(distances, 0.5);
  residuals.surface_p90_m = percentile(distances, 0.9);
  double capped_sum = double(model.fit_vertices.size() - distances.size()) * options.final_distance_m;
  for (const double d : distances) capped_sum += std::min(d, options.final_distance_m);
  residuals.surface_capped_mean_m = capped_sum / double(std::max<size_t>(1, model.fit_vertices.size()));
}

std::vector<bool> visible_from(const Eigen::Vector3d& eye, const PosedModel& posed, const std::vector<int>& vertices,
                               const SurfaceQuery& scan) {
  const std::vector<Eigen::Vector3d> points = rows_of(posed.world, vertices);
  std::vector<bool> visible = scan.occluded(eye, points, kOcclusionMarginM);
  for (size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector3d to_eye = (eye - points[i]).normalized();
    const Eigen::Vector3d normal = posed.normals.row(vertices[i]).cast<double>().transpose();
    visible[i] = !visible[i] && normal.dot(to_eye) > kMinFacingCosine;
  }
  return visible;
}

Term<ImageTarget> landmark_targets(const HeadModel& model, const PosedModel& posed, const FrameObservation& frame,
                                   const std::vector<Camera>& cameras, const SurfaceQuery& scan,
                                   const landmarks::LandmarkDetector& detector, const LandmarkOptions& options) {
  Term<ImageTarget> term;
  term.scale = scale_of(options.term);
  if (model.landmark_vertices.empty()) return term;
  std::mutex mutex;
  ThreadPool pool(0);
  pool.parallel_for(0, int64_t(cameras.size()), [&](int64_t c) {
    const Image8& image = frame.images.at(size_t(c));
    if (image.pixels.empty()) return;
    const Camera& camera = cameras[size_t(c)];
    landmarks::FaceBox box;
    for (int v : model.landmark_vertices) {
      const auto pixel = camera.project(posed.world.row(v).cast<double>().transpose());
      if (!pixel) return;
      box.extend(*pixel);
    }
    box = grown_landmark_box(box);
    if (!box.intersects(landmarks::FaceBox(Eigen::Vector2d::Zero(), Eigen::Vector2d(image.width, image.height)))) return;
    const auto found = detector.detect(image, options.detector_boxes ? std::nullopt : std::optional<landmarks::FaceBox>(box));
    if (!found) return;
    const std::vector<int> inner(model.landmark_vertices.begin() + kFirstInnerLandmark, model.landmark_vertices.end());
    const std::vector<bool> visible = visible_from(camera.center(), posed, inner, scan);
    std::lock_guard lock(mutex);
    for (size_t i = 0; i < inner.size(); ++i) {
      const int point = kFirstInnerLandmark + int(i);
      const bool ignored = std::find(options.ignored_points.begin(), options.ignored_points.end(), point) !=
                           options.ignored_points.end();
      if (visible[i] && !ignored) term.targets.push_back({inner[i], int(c), (*found)[size_t(point)]});
    }
  });
  sort_targets(term);
  return term;
}

Term<ImageTarget> flow_targets(const HeadModel& model, const PosedModel& previous, const SurfaceQuery& previous_scan,
                               const std::vector<Image8>& previous_images, const std::vector<Image8>& images,
                               const std::vector<Camera>& cameras, const FlowOptions& options) {
  Term<ImageTarget> term;
  term.scale = scale_of(options.term);
  std::vector<int> sampled;
  for (size_t i = 0; i < model.fit_vertices.size(); i += size_t(std::max(1, options.vertex_step)))
    sampled.push_back(model.fit_vertices[i]);
  std::mutex mutex;
  ThreadPool pool(0);
  pool.parallel_for(0, int64_t(cameras.size()), [&](int64_t c) {
    const Image8& from = previous_images.at(size_t(c));
    const Image8& to = images.at(size_t(c));
    if (from.pixels.empty() || to.pixels.empty()) return;
    const Camera& camera = cameras[size_t(c)];
    const std::vector<bool> visible = visible_from(camera.center(), previous, sampled, previous_scan);
    const FlowField flow(from, to, options.max_image_side);
    std::vector<ImageTarget> found;
    for (size_t i = 0; i < sampled.size(); ++i) {
      if (!visible[i]) continue;
      const auto pixel = camera.project(previous.world.row(sampled[i]).cast<double>().transpose());
      if (!pixel) continue;
      const auto moved = flow.follow(*pixel, options.max_forward_backward_px);
      if (moved) found.push_back({sampled[i], int(c), *moved});
    }
    std::lock_guard lock(mutex);
    term.targets.insert(term.targets.end(), found.begin(), found.end());
  });
  sort_targets(term);
  return term;
}

double reprojection_rms(const Term<ImageTarget>& term, const Vertices& world, const std::vector<Camera>& cameras) {
  if (term.targets.empty()) return -1;
  double sum = 0;
  int count = 0;
  for (const auto& t : term.targets) {
    const auto pixel = cameras[size_t(t.camera)].project(world.row(t.vertex).cast<double>().transpose());
    if (!pixel) continue;
    sum += (*pixel - t.pixel).squaredNorm();
    ++count;
  }
  return count ? std::sqrt(sum / count) : -1;
}

}  // namespace tega::tracking
