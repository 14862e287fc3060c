#include "tega/trainer/densifier.h"

#include <ATen/core/grad_mode.h>

#include <cmath>

#include "tega/uvd/covariance.h"

namespace tega::trainer {

void DensifyStats::reset(int64_t n, const at::Device& device) {
  gradient_norm_sum = at::zeros({n}, at::TensorOptions(at::kFloat).device(device));
  visible_count = at::zeros({n}, at::TensorOptions(at::kInt).device(device));
  world_std = at::zeros({n}, at::TensorOptions(at::kFloat).device(device));
}

namespace {

// Rows [keep] of a per-Gaussian tensor followed by `appended` (undefined: none).
at::Tensor kept_and_appended(const at::Tensor& rows, const at::Tensor& keep, const at::Tensor& appended) {
  const at::Tensor kept = rows.index_select(0, keep);
  return appended.defined() && appended.size(0) > 0 ? at::cat({kept, appended}) : kept;
}

// Rows [keep] of every parameter followed by `appended` rows (none when
// empty); the moments and the per-Gaussian triangles follow.
void rebuild(Gaussians& g, Adam& adam, const at::Tensor& keep, const std::map<std::string, at::Tensor>& appended,
             const at::Tensor& appended_bound, const at::Tensor& appended_birth) {
  const int64_t added = appended.empty() ? 0 : appended.begin()->second.size(0);
  for (const auto& name : Gaussians::parameter_names()) {
    at::Tensor& p = g.parameter(name);
    const at::Tensor kept = p.detach().index_select(0, keep);
    at::Tensor next = (added > 0 ? at::cat({kept, appended.at(name)}) : kept).requires_grad_(true);
    adam.replace_rows(name, next, keep, added);
    p = next;
  }
  if (g.bound_triangle.defined()) g.bound_triangle = kept_and_appended(g.bound_triangle, keep, appended_bound);
  if (g.birth_triangle.defined()) g.birth_triangle = kept_and_appended(g.birth_triangle, keep, appended_birth);
}

}  // namespace

DensifyResult densify(Gaussians& g, Adam& adam, const DensifyStats& stats, const DensifyOptions& options,
                      const uvd::UvTriangleLookup& lookup, int64_t latent_side, at::Generator& generator) {
  at::NoGradGuard no_grad;
  const int64_t n = g.size();
  const at::Tensor mean_gradient = stats.gradient_norm_sum / stats.visible_count.clamp_min(1).to(at::kFloat);
  const at::Tensor large = stats.world_std > options.clone_max_std;
  at::Tensor candidates = (mean_gradient >= options.gradient_threshold).logical_and(stats.visible_count > 0);

  const at::Tensor opacity = at::sigmoid(g.opacity_logit);
  const at::Tensor prune = (opacity < options.prune_opacity).logical_or(stats.world_std > options.prune_max_std);
  candidates = candidates.logical_and(prune.logical_not());

  // Each clone or split adds one Gaussian; prunes free room first.
  const int64_t room = std::max<int64_t>(0, options.max_gaussians - (n - prune.sum().item<int64_t>()));
  if (candidates.sum().item<int64_t>() > room) {
    const at::Tensor score = at::where(candidates, mean_gradient, at::full_like(mean_gradient, -1.0));
    const at::Tensor best = std::get<1>(score.topk(room));
    candidates = at::zeros_like(candidates).index_fill_(0, best, true);
  }
  const at::Tensor clone = candidates.logical_and(large.logical_not());
  const at::Tensor split = candidates.logical_and(large);
  const at::Tensor clone_ids = clone.nonzero().flatten();
  const at::Tensor split_ids = split.nonzero().flatten();

  // Split children: two samples from N(μ_uvd, Σ_uvd), each with std / 1.6.
  const at::Tensor parents = split_ids.repeat({2});
  const at::Tensor rotation = uvd::rotation_from_quaternion(g.rotation.index_select(0, parents));
  const at::Tensor scale = g.log_scale.index_select(0, parents).exp();
  // The run's generator is a CPU one (runs reproduce on the CPU), so the noise is drawn there.
  const at::Tensor z = at::randn({parents.size(0), 3, 1}, generator, g.uvd.options().device(at::kCPU)).to(g.uvd.device());
  at::Tensor child_uvd = g.uvd.index_select(0, parents) + rotation.bmm(scale.unsqueeze(2) * z).squeeze(2);
  if (!g.bound_triangle.defined() && child_uvd.size(0) > 0) {
    child_uvd = at::cat({lookup.project_to_valid_uv(child_uvd.slice(1, 0, 2)), child_uvd.slice(1, 2, 3)}, 1);
  }

  std::map<std::string, at::Tensor> appended;
  for (const auto& name : Gaussians::parameter_names()) {
    const at::Tensor& p = g.parameter(name);
    at::Tensor children = p.index_select(0, parents);
    if (name == "uvd") children = child_uvd;
    if (name == "log_scale") children = children - std::log(1.6);
    appended[name] = at::cat({p.index_select(0, clone_ids), children}).detach();
  }
  at::Tensor appended_bound, appended_birth;
  if (g.bound_triangle.defined()) {
    appended_bound = at::cat({g.bound_triangle.index_select(0, clone_ids), g.bound_triangle.index_select(0, parents)});
  }
  if (g.birth_triangle.defined() && appended.at("uvd").size(0) > 0) {
    appended_birth = lookup.lookup(appended.at("uvd").slice(1, 0, 2)).triangle;
  }
  const at::Tensor keep = split.logical_or(prune).logical_not().nonzero().flatten();
  rebuild(g, adam, keep, appended, appended_bound, appended_birth);
  // The new rows went to the end: back into order (see gaussians.h).
  rebuild(g, adam, gaussian_order(g, latent_side), {}, {}, {});

  DensifyResult r;
  r.cloned = clone_ids.size(0);
  r.split = split_ids.size(0);
  r.pruned = prune.sum().item<int64_t>();
  return r;
}

void reset_opacity(Gaussians& g, Adam& adam) {
  at::NoGradGuard no_grad;
  g.opacity_logit.clamp_max_(std::log(0.01 / 0.99));
  adam.reset_rows("opacity_logit", at::arange(g.size(), at::TensorOptions(at::kLong).device(g.uvd.device())));
}

void clamp_world_size(Gaussians& g, const at::Tensor& world_std_per_scale, double min_std, double max_std) {
  at::NoGradGuard no_grad;
  const at::Tensor log_factor = world_std_per_scale.clamp_min(1e-12).log();
  g.log_scale.copy_(at::max(at::min(g.log_scale, std::log(max_std) - log_factor), std::log(min_std) - log_factor));
}

}  // namespace tega::trainer
