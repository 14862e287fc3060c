#include "tega/mvs/patch_match.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <utility>

#include "patch_match_backend.h"
#include "pyramid.h"
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
  if (options.pyramid_levels < 0 || options.refine_passes < 1 || options.refine_iterations < 1)
    throw Error("patch match: pyramid_levels must be at least 0, refine_passes and refine_iterations at least 1");
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

namespace {

struct Solver {
  const std::vector<ViewTask>& tasks;
  Device device;
  ThreadPool& pool;
  Progress* progress;

  std::unique_ptr<detail::PatchMatchBackend> backend(const std::vector<StereoView>& views) const {
    return device == Device::cuda ? detail::make_cuda_backend(views) : detail::make_cpu_backend(views, pool);
  }

  // One pass over every task: photometric from random hypotheses, or
  // geometric against the sources' current estimates.
  void pass(detail::PatchMatchBackend& backend, const PatchMatchOptions& options, bool geometric,
            int first_iteration, int iterations) const {
    for (const auto& task : tasks) {
      detail::Parameters p = parameters(options, task);
      p.geometric = geometric;
      backend.run(task, p, first_iteration, iterations);
      if (progress) progress->advance();
    }
    backend.finish_pass();
  }

  // The backend holding every task's estimate (before the cost limit), and
  // the iterations run.
  std::pair<std::unique_ptr<detail::PatchMatchBackend>, int> solve(const std::vector<StereoView>& views,
                                                                   const PatchMatchOptions& options,
                                                                   int levels) const {
    if (levels > 0) return refine(views, options, levels);
    auto run = backend(views);
    pass(*run, options, false, 0, options.iterations);
    for (int p = 0; p < options.geometric_passes; ++p)
      pass(*run, options, true, options.iterations + p * options.geometric_iterations, options.geometric_iterations);
    return {std::move(run), options.iterations + options.geometric_passes * options.geometric_iterations};
  }

  // The estimate at half size, its planes carried up, then geometric passes
  // at this size. The window covers the same part of the scene at both sizes.
  std::pair<std::unique_ptr<detail::PatchMatchBackend>, int> refine(const std::vector<StereoView>& views,
                                                                    const PatchMatchOptions& options,
                                                                    int levels) const {
    std::vector<StereoView> half(views.size());
    pool.parallel_for(0, int64_t(views.size()), [&](int64_t k) { half[size_t(k)] = detail::half_size(views[size_t(k)]); });
    PatchMatchOptions coarse = options;
    coarse.window_radius = std::max(1, options.window_radius / 2);
    coarse.window_step = std::max(1, options.window_step / 2);
    // Halving rounds down: the samples a side must stay within the window's limit (3 each side).
    coarse.window_radius = std::min(coarse.window_radius, 3 * coarse.window_step);
    coarse.sigma_spatial = 0.5f * options.sigma_spatial;
    auto [coarse_backend, iterations] = solve(half, coarse, levels - 1);

    const detail::PatchMatchBackend& coarse_estimates = *coarse_backend;
    std::vector<DepthMap> up(tasks.size());
    pool.parallel_for(0, int64_t(tasks.size()), [&](int64_t t) {
      const ViewTask& task = tasks[size_t(t)];
      up[size_t(t)] = detail::upsampled(coarse_estimates.estimate(task.reference), half[task.reference].camera,
                                        views[task.reference], parameters(options, task));
    });
    coarse_backend.reset();
    auto run = backend(views);
    for (size_t t = 0; t < tasks.size(); ++t) run->set_estimate(tasks[t].reference, up[t]);
    up.clear();
    for (int p = 0; p < options.refine_passes; ++p)
      pass(*run, options, true, iterations + p * options.refine_iterations, options.refine_iterations);
    return {std::move(run), iterations + options.refine_passes * options.refine_iterations};
  }
};

}  // namespace

std::vector<DepthMap> estimate_depth_maps(const std::vector<StereoView>& views, const std::vector<ViewTask>& tasks,
                                          const PatchMatchOptions& options, Device device, ThreadPool* pool,
                                          Progress* progress) {
  check_input(views, tasks, options);
  std::optional<ThreadPool> own_pool;
  if (!pool) pool = &own_pool.emplace(0);
  const auto estimates = Solver{tasks, device, *pool, progress}.solve(views, options, options.pyramid_levels).first;
  std::vector<DepthMap> maps(tasks.size());
  for (size_t t = 0; t < tasks.size(); ++t) maps[t] = estimates->estimate(tasks[t].reference);
  pool->parallel_for(0, int64_t(maps.size()), [&](int64_t t) { drop_costly(maps[size_t(t)], options.max_cost); });
  return maps;
}

}  // namespace tega::mvs
