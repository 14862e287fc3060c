#include "tega/trainer/gaussians.h"

#include <ATen/core/grad_mode.h>

#include <cmath>

#include "tega/core/error.h"

namespace tega::trainer {

const std::vector<std::string>& Gaussians::parameter_names() {
  static const std::vector<std::string> names{"uvd", "log_scale", "rotation", "sh_dc", "sh_rest", "opacity_logit"};
  return names;
}

at::Tensor& Gaussians::parameter(const std::string& name) {
  if (name == "uvd") return uvd;
  if (name == "log_scale") return log_scale;
  if (name == "rotation") return rotation;
  if (name == "sh_dc") return sh_dc;
  if (name == "sh_rest") return sh_rest;
  if (name == "opacity_logit") return opacity_logit;
  throw Error("no Gaussian parameter '" + name + "'");
}

std::map<std::string, at::Tensor> Gaussians::tensors() const {
  std::map<std::string, at::Tensor> t{{"gaussians.uvd", uvd},
                                      {"gaussians.log_scale", log_scale},
                                      {"gaussians.rotation", rotation},
                                      {"gaussians.sh_dc", sh_dc},
                                      {"gaussians.sh_rest", sh_rest},
                                      {"gaussians.opacity_logit", opacity_logit}};
  if (bound_triangle.defined()) t["gaussians.bound_triangle"] = bound_triangle;
  if (birth_triangle.defined()) t["gaussians.birth_triangle"] = birth_triangle;
  return t;
}

at::Tensor uv_order(const at::Tensor& uv, int64_t latent_side) {
  TORCH_CHECK(latent_side >= 1, "uv_order: latent_side must be positive, got ", latent_side);
  // The top-left tap's column and row, as sample_latent finds them: texel
  // centres at (c + 0.5)/W and v = 1 - (r + 0.5)/H, clamped at the border.
  const at::Tensor u = uv.select(1, 0).detach(), v = uv.select(1, 1).detach();
  const auto tap = [&](const at::Tensor& pixel) { return pixel.floor().clamp(0, latent_side - 1).to(at::kLong); };
  const at::Tensor column = tap(u * latent_side - 0.5), row = tap((1 - v) * latent_side - 0.5);
  return std::get<1>((row * latent_side + column).sort(/*stable=*/true, /*dim=*/0, /*descending=*/false));
}

Gaussians initialise_gaussians(const uvd::UvTriangleLookup& lookup, int64_t count, double metres_per_uv,
                               bool bind_to_triangles, int64_t latent_side, uint64_t seed,
                               const at::TensorOptions& options) {
  at::NoGradGuard no_grad;
  Gaussians g;
  const at::Tensor sampled = lookup.sample_uniform(count, seed).to(options);
  const at::Tensor uv = sampled.index_select(0, uv_order(sampled, latent_side));
  g.uvd = at::cat({uv, at::zeros({count, 1}, options)}, 1);
  // Mean spacing of `count` points over the valid UV area.
  const double uv_area = lookup.uv_area().sum().item<double>();
  const double spacing_uv = std::sqrt(uv_area / static_cast<double>(count));
  const double spacing_m = spacing_uv * metres_per_uv;
  g.log_scale = at::tensor({std::log(spacing_uv), std::log(spacing_uv), std::log(spacing_m)}, options)
                    .repeat({count, 1});
  g.rotation = at::zeros({count, 4}, options);
  g.rotation.select(1, 0).fill_(1.0);
  g.sh_dc = at::zeros({count, 1, 3}, options);  // colour 0.5
  g.sh_rest = at::zeros({count, 15, 3}, options);
  g.opacity_logit = at::full({count}, std::log(0.1 / 0.9), options);
  (bind_to_triangles ? g.bound_triangle : g.birth_triangle) = lookup.lookup(uv).triangle;
  for (const auto& name : Gaussians::parameter_names()) g.parameter(name).requires_grad_(true);
  return g;
}

Gaussians initialise_rigged_gaussians(const uvd::UvTriangleLookup& lookup, const at::TensorOptions& options) {
  at::NoGradGuard no_grad;
  Gaussians g;
  g.rigged = true;
  g.bound_triangle = (lookup.uv_area() > 0).nonzero().flatten().to(options.device());
  const int64_t count = g.bound_triangle.size(0);
  g.uvd = at::zeros({count, 3}, options);
  g.log_scale = at::full({count, 3}, std::log(0.5), options);
  g.rotation = at::zeros({count, 4}, options);
  g.rotation.select(1, 0).fill_(1.0);
  g.sh_dc = at::zeros({count, 1, 3}, options);
  g.sh_rest = at::zeros({count, 15, 3}, options);
  g.opacity_logit = at::full({count}, std::log(0.1 / 0.9), options);
  for (const auto& name : Gaussians::parameter_names()) g.parameter(name).requires_grad_(true);
  return g;
}

at::Tensor gaussian_order(const Gaussians& g, int64_t latent_side) {
  if (!g.rigged) return uv_order(g.uvd, latent_side);
  return std::get<1>(g.bound_triangle.sort(/*stable=*/true, /*dim=*/0, /*descending=*/false));
}

Gaussians gaussians_from_tensors(const std::map<std::string, at::Tensor>& tensors, const at::Device& device,
                                 bool rigged, int64_t triangles) {
  Gaussians g;
  g.rigged = rigged;
  for (const auto& name : Gaussians::parameter_names()) {
    auto it = tensors.find("gaussians." + name);
    if (it == tensors.end()) throw Error("checkpoint has no tensor 'gaussians." + name + "'");
    g.parameter(name) = it->second.to(device).detach().requires_grad_(true);
  }
  // Triangle indices, checked here: the GPU's uvd -> world reads its tables at them unchecked.
  const auto triangle_indices = [&](const std::string& name) {
    auto it = tensors.find("gaussians." + name);
    if (it == tensors.end()) return at::Tensor();
    const at::Tensor& t = it->second;
    if (t.dim() != 1 || t.size(0) != g.uvd.size(0))
      throw Error("checkpoint's 'gaussians." + name + "' is not one index per Gaussian");
    if (t.numel() > 0 && (t.min().item<int64_t>() < 0 || t.max().item<int64_t>() >= triangles))
      throw Error("checkpoint's 'gaussians." + name + "' holds triangle indices outside the template's " +
                  std::to_string(triangles) + " triangles");
    return t.to(device);
  };
  g.bound_triangle = triangle_indices("bound_triangle");
  g.birth_triangle = triangle_indices("birth_triangle");
  if (rigged && !g.bound_triangle.defined()) throw Error("checkpoint of a rigged run has no 'gaussians.bound_triangle'");
  return g;
}

}  // namespace tega::trainer
