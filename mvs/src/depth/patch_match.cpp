#include "tega/mvs/patch_match.h"

#include <algorithm>
#include <optional>

#include "patch_match_backend.h"
#include "tega/core/error.h"
#include "tega/core/progress.h"
#include "tega/core/thread_pool.h"

namespace tega::mvs {
namespace detail {
namespace {

void copy_matrix(const Eigen::Matrix3d& m, float* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[r * 3 + c] = static_cast<float>(m(r, c));
}

void copy_vector(const Eigen::Vector3d& v, float* out) {
  for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(v(k));
}

}  // namespace

ReferenceView reference_geometry(const Camera& camera) {
  ReferenceView ref;
  copy_matrix(camera.K, ref.K);
  copy_matrix(camera.K.inverse(), ref.K_inverse);
  return ref;
}

SourceView source_geometry(const Camera& reference, const Camera& source) {
  const RigidTransform to_source = source.world_to_camera * reference.world_to_camera.inverse();
  const RigidTransform back = to_source.inverse();
  SourceView s;
  copy_matrix(source.K, s.K);
  copy_matrix(source.K.inverse(), s.K_inverse);
  copy_matrix(to_source.R, s.R);
  copy_vector(to_source.t, s.t);
  copy_matrix(back.R, s.R_back);
  copy_vector(back.t, s.t_back);
  return s;
}

}  // namespace detail

namespace {

void check_input(const std::vector<StereoView>& views, const std::vector<ViewTask>& tasks,
                 const PatchMatchOptions& options) {
  for (const auto& view : views) {
    const auto& c = view.camera;
    if (view.grey.width != c.width || view.grey.height != c.height || view.grey.channels != 1)
      throw Error("patch match: view " + c.name + ": its grey image is " + std::to_string(view.grey.width) + "x" +
                  std::to_string(view.grey.height) + "x" + std::to_string(view.grey.channels) + ", the camera " +
                  std::to_string(c.width) + "x" + std::to_string(c.height) + "x1");
    if (!view.mask.empty() && view.mask.size() != size_t(c.width) * c.height)
      throw Error("patch match: view " + c.name + ": its mask does not have one value per pixel");
    if (c.has_distortion()) throw Error("patch match: view " + c.name + ": the camera must be undistorted");
  }
  std::vector<bool> referenced(views.size(), false);
  for (const auto& task : tasks) {
    const auto valid = [&](int v) { return v >= 0 && v < static_cast<int>(views.size()); };
    if (!valid(task.reference)) throw Error("patch match: a task's reference view is out of range");
    if (referenced[size_t(task.reference)])
      throw Error("patch match: view " + views[task.reference].camera.name + " is the reference of two tasks");
    referenced[size_t(task.reference)] = true;
    if (task.sources.empty())
      throw Error("patch match: view " + views[task.reference].camera.name + " has no source view");
    if (static_cast<int>(task.sources.size()) > detail::kMaxSources)
      throw Error("patch match: view " + views[task.reference].camera.name + " has more than " +
                  std::to_string(detail::kMaxSources) + " source views");
    for (int s : task.sources)
      if (!valid(s) || s == task.reference)
        throw Error("patch match: view " + views[task.reference].camera.name + " has an invalid source view");
    if (!(task.depth_min > 0 && task.depth_max > task.depth_min))
      throw Error("patch match: view " + views[task.reference].camera.name + ": the depth range must be 0 < min < max");
  }
  const int samples = 2 * (options.window_radius / std::max(options.window_step, 1)) + 1;
  if (options.window_step < 1 || options.window_radius < 1 || samples * samples > detail::kMaxWindowSamples)
    throw Error("patch match: the window (radius " + std::to_string(options.window_radius) + ", step " +
                std::to_string(options.window_step) + ") must have 3 to 7 samples a side");
  if (options.top_k < 1 || options.iterations < 1 || options.geometric_passes < 0 || options.geometric_iterations < 1)
    throw Error("patch match: top_k, iterations and geometric_iterations must be at least 1");
}

detail::Parameters parameters(const PatchMatchOptions& o, const ViewTask& task) {
  detail::Parameters p;
  p.window_half_samples = o.window_radius / o.window_step;
  p.window_step = o.window_step;
  p.sigma_spatial = o.sigma_spatial;
  p.sigma_color = o.sigma_color;
  p.depth_min = task.depth_min;
  p.depth_max = task.depth_max;
  p.num_sources = static_cast<int>(task.sources.size());
  p.top_k = std::min<int>(o.top_k, p.num_sources);
  p.geometric_weight = o.geometric_weight;
  p.geometric_max_error = o.geometric_max_error_px;
  p.seed = static_cast<uint32_t>(o.seed);
  p.num_iterations = o.iterations + o.geometric_passes * o.geometric_iterations;
  return p;
}

void drop_costly(DepthMap& map, float max_cost) {
  for (size_t i = 0; i < map.depth.size(); ++i) {
    if (map.depth[i] > 0 && map.cost[i] <= max_cost) continue;
    map.depth[i] = 0;
    map.normals[3 * i] = map.normals[3 * i + 1] = map.normals[3 * i + 2] = 0;
  }
}

}  // namespace

Device parse_device(const std::string& name) {
  if (name == "cpu") return Device::cpu;
  if (name == "cuda") return Device::cuda;
  throw Error("unknown device '" + name + "' (expected cpu or cuda)");
}

std::vector<DepthMap> estimate_depth_maps(const std::vector<StereoView>& views, const std::vector<ViewTask>& tasks,
                                          const PatchMatchOptions& options, Device device, ThreadPool* pool,
                                          Progress* progress) {
  check_input(views, tasks, options);
  std::optional<ThreadPool> own_pool;
  if (!pool && device == Device::cpu) pool = &own_pool.emplace(0);
  auto backend = device == Device::cuda ? detail::make_cuda_backend(views) : detail::make_cpu_backend(views, *pool);

  // By view, so that a geometric pass finds every source's last estimate.
  std::vector<DepthMap> by_view(views.size());
  for (const auto& task : tasks) {
    by_view[task.reference] = backend->run(task, parameters(options, task), {}, 0, options.iterations);
    if (progress) progress->advance();
  }
  for (int pass = 0; pass < options.geometric_passes; ++pass) {
    std::vector<DepthMap> next(views.size());
    for (const auto& task : tasks) {
      detail::Parameters p = parameters(options, task);
      p.geometric = true;
      next[task.reference] = backend->run(task, p, by_view, options.iterations + pass * options.geometric_iterations,
                                          options.geometric_iterations);
      if (progress) progress->advance();
    }
    by_view = std::move(next);
  }
  std::vector<DepthMap> maps;
  maps.reserve(tasks.size());
  for (const auto& task : tasks) {
    maps.push_back(std::move(by_view[task.reference]));
    drop_costly(maps.back(), options.max_cost);
  }
  return maps;
}

}  // namespace tega::mvs
