// rasterize(): input checks, the autograd Function and the dispatch between
// the CPU and CUDA pipelines.

#include <tega/splat/rasterize.h>

#include "raster_glue.h"

#include <torch/csrc/autograd/custom_function.h>

#include <string>

#include "tega/avatar/device_dispatch.h"

namespace tega::splat {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

glue::ForwardTensors run_forward(const glue::RasterTensors& t, const glue::CallConfig& config) {
  if (use_cuda_kernels(t.means, "tega splat")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return glue::forward_cuda(t, config);
#endif
  }
  return glue::forward_cpu(t, config);
}

glue::InputGradTensors run_backward(const glue::RasterTensors& t, const glue::CallConfig& config,
                                    const glue::ForwardTensors& saved, const glue::ImageGradTensors& grads,
                                    const MeanGradientStats* stats) {
  if (use_cuda_kernels(t.means, "tega splat")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return glue::backward_cuda(t, config, saved, grads, stats);
#endif
  }
  return glue::backward_cpu(t, config, saved, grads, stats);
}

// The call's configuration travels to the backward pass through saved_data
// (IValues only): cameras as a [C, 16] double tensor, settings as scalars.
void save_config(AutogradContext* ctx, const glue::CallConfig& config) {
  at::Tensor cameras = at::empty({int64_t(config.cameras.size()), 16}, at::TensorOptions().dtype(at::kDouble));
  double* p = cameras.data_ptr<double>();
  for (const RasterCamera& cam : config.cameras) {
    for (double r : cam.rotation) *p++ = r;
    for (double t : cam.translation) *p++ = t;
    *p++ = cam.fx;
    *p++ = cam.fy;
    *p++ = cam.cx;
    *p++ = cam.cy;
  }
  const RasterSettings& s = config.settings;
  ctx->saved_data["cameras"] = cameras;
  ctx->saved_data["width"] = int64_t(s.width);
  ctx->saved_data["height"] = int64_t(s.height);
  ctx->saved_data["near"] = s.near_plane;
  ctx->saved_data["far"] = s.far_plane;
  ctx->saved_data["antialiased"] = s.antialiased;
  ctx->saved_data["sh_degree"] = int64_t(s.sh_degree);
  ctx->saved_data["per_camera_rgb"] = s.per_camera_rgb;
}

glue::CallConfig load_config(AutogradContext* ctx) {
  glue::CallConfig config;
  const at::Tensor cameras = ctx->saved_data["cameras"].toTensor();
  const double* p = cameras.data_ptr<double>();
  config.cameras.resize(cameras.size(0));
  for (RasterCamera& cam : config.cameras) {
    for (double& r : cam.rotation) r = *p++;
    for (double& t : cam.translation) t = *p++;
    cam.fx = *p++;
    cam.fy = *p++;
    cam.cx = *p++;
    cam.cy = *p++;
  }
  RasterSettings& s = config.settings;
  s.width = int(ctx->saved_data["width"].toInt());
  s.height = int(ctx->saved_data["height"].toInt());
  s.near_plane = ctx->saved_data["near"].toDouble();
  s.far_plane = ctx->saved_data["far"].toDouble();
  s.antialiased = ctx->saved_data["antialiased"].toBool();
  s.sh_degree = int(ctx->saved_data["sh_degree"].toInt());
  s.per_camera_rgb = ctx->saved_data["per_camera_rgb"].toBool();
  return config;
}

class RasterizeFunction : public torch::autograd::Function<RasterizeFunction> {
 public:
  // Returns rgb, alpha, the expected depth and radii.
  static variable_list forward(AutogradContext* ctx, const at::Tensor& means, const at::Tensor& covariances,
                               const at::Tensor& colors, const at::Tensor& opacities, const at::Tensor& background,
                               const glue::CallConfig& config, const MeanGradientStats& stats) {
    const glue::RasterTensors t{means, covariances, colors, opacities, background};
    glue::ForwardTensors f = run_forward(t, config);
    ctx->save_for_backward({means, covariances, colors, opacities, background, f.radii, f.splats,
                            f.color_jacobians, f.depth, f.final_transmittance, f.last, f.ranges, f.gaussian_ids});
    save_config(ctx, config);
    if (stats.grad_norm_sum.defined()) {
      ctx->saved_data["stats_sum"] = stats.grad_norm_sum;
      ctx->saved_data["stats_count"] = stats.visible_count;
    }
    ctx->mark_non_differentiable({f.radii});
    // An output the loss does not use gets an undefined gradient rather than
    // zeros: without depth in the loss, the backward pass skips its terms.
    ctx->set_materialize_grads(false);
    return {f.rgb, f.alpha, f.depth, f.radii};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grad_outputs) {
    const variable_list saved = ctx->get_saved_variables();
    const glue::RasterTensors t{saved[0], saved[1], saved[2], saved[3], saved[4]};
    glue::ForwardTensors f;
    f.radii = saved[5];
    f.splats = saved[6];
    f.color_jacobians = saved[7];
    f.depth = saved[8];
    f.final_transmittance = saved[9];
    f.last = saved[10];
    f.ranges = saved[11];
    f.gaussian_ids = saved[12];
    const at::Tensor& transmittance = f.final_transmittance;  // [C, H, W]
    const auto defined_or_zeros = [&](const at::Tensor& grad, at::IntArrayRef shape) {
      return grad.defined() ? grad.contiguous() : at::zeros(shape, transmittance.options());
    };
    const glue::ImageGradTensors grads{
        defined_or_zeros(grad_outputs[0], {transmittance.size(0), transmittance.size(1), transmittance.size(2), 3}),
        defined_or_zeros(grad_outputs[1], transmittance.sizes()),
        grad_outputs[2].defined() ? grad_outputs[2].contiguous() : at::Tensor()};
    MeanGradientStats stats;
    const bool has_stats = ctx->saved_data.count("stats_sum") > 0;
    if (has_stats) {
      stats.grad_norm_sum = ctx->saved_data["stats_sum"].toTensor();
      stats.visible_count = ctx->saved_data["stats_count"].toTensor();
    }
    const glue::InputGradTensors g = run_backward(t, load_config(ctx), f, grads, has_stats ? &stats : nullptr);
    return {g.means, g.covariances, g.colors, g.opacities, g.background, at::Tensor(), at::Tensor()};
  }
};

void check_tensor(const at::Tensor& t, const char* name, std::initializer_list<int64_t> shape,
                  const at::Tensor& like) {
  TORCH_CHECK(t.defined(), "rasterize: ", name, " is undefined");
  TORCH_CHECK(t.sizes().equals(shape), "rasterize: ", name, " has shape ", t.sizes(), ", expected ",
              at::IntArrayRef(shape));
  TORCH_CHECK(t.scalar_type() == like.scalar_type() && t.device() == like.device(), "rasterize: ", name,
              " must have the means' dtype and device");
}

void validate(const at::Tensor& means, const at::Tensor& covariances, const at::Tensor& colors,
              const at::Tensor& opacities, const at::Tensor& background, const std::vector<RasterCamera>& cameras,
              const RasterSettings& s, const MeanGradientStats* stats) {
  TORCH_CHECK(means.defined() && means.dim() == 2 && means.size(1) == 3, "rasterize: means must be [N, 3]");
  TORCH_CHECK(means.scalar_type() == at::kFloat || (means.scalar_type() == at::kDouble && !means.is_cuda()),
              "rasterize: tensors must be float32 (or float64 on the CPU)");
  const int64_t n = means.size(0), c = int64_t(cameras.size());
  TORCH_CHECK(c > 0, "rasterize: no cameras");
  TORCH_CHECK(s.width > 0 && s.height > 0, "rasterize: image size must be positive");
  TORCH_CHECK(s.near_plane > 0 && s.far_plane > s.near_plane, "rasterize: need 0 < near < far");
  check_tensor(covariances, "covariances", {n, 6}, means);
  check_tensor(opacities, "opacities", {n}, means);
  check_tensor(background, "background", {3}, means);
  if (s.per_camera_rgb) {
    check_tensor(colors, "colors", {c, n, 3}, means);
  } else if (colors.dim() == 2) {
    check_tensor(colors, "colors", {n, 3}, means);
  } else {
    TORCH_CHECK(s.sh_degree >= 0 && s.sh_degree <= 3, "rasterize: sh_degree must be in [0, 3]");
    const int64_t needed = int64_t(s.sh_degree + 1) * (s.sh_degree + 1);
    TORCH_CHECK(colors.dim() == 3 && colors.size(0) == n && colors.size(2) == 3 && colors.size(1) >= needed &&
                    colors.size(1) <= kMaxShCoefficients,
                "rasterize: SH colours must be [N, K, 3] with (sh_degree+1)² <= K <= 16");
    check_tensor(colors, "colors", {n, colors.size(1), 3}, means);
  }
  if (stats) {
    check_tensor(stats->grad_norm_sum, "stats.grad_norm_sum", {n}, means);
    TORCH_CHECK(stats->visible_count.sizes().equals({n}) && stats->visible_count.scalar_type() == at::kInt &&
                    stats->visible_count.device() == means.device(),
                "rasterize: stats.visible_count must be int32 [N] on the means' device");
    TORCH_CHECK(stats->grad_norm_sum.is_contiguous() && stats->visible_count.is_contiguous(),
                "rasterize: stats tensors must be contiguous");
  }
}

}  // namespace

MeanGradientStats MeanGradientStats::zeros(const at::Tensor& means) {
  return {at::zeros({means.size(0)}, means.options()), at::zeros({means.size(0)}, means.options().dtype(at::kInt))};
}

RasterOutput rasterize(const at::Tensor& means, const at::Tensor& covariances, const at::Tensor& colors,
                       const at::Tensor& opacities, const at::Tensor& background,
                       const std::vector<RasterCamera>& cameras, const RasterSettings& settings,
                       const MeanGradientStats* stats) {
  validate(means, covariances, colors, opacities, background, cameras, settings, stats);
  const glue::CallConfig config{cameras, settings};
  const variable_list out = RasterizeFunction::apply(means.contiguous(), covariances.contiguous(), colors.contiguous(),
                                                     opacities.contiguous(), background.contiguous(), config,
                                                     stats ? *stats : MeanGradientStats{});
  RasterOutput result;
  result.rgb = out[0];
  result.alpha = out[1];
  result.depth = out[2];
  result.radii = out[3];
  result.visible = result.radii > 0;
  return result;
}

at::Tensor covariance_from_scale_rotation(const at::Tensor& scales, const at::Tensor& quaternions) {
  TORCH_CHECK(scales.dim() == 2 && scales.size(1) == 3, "covariance_from_scale_rotation: scales must be [N, 3]");
  TORCH_CHECK(quaternions.dim() == 2 && quaternions.size(1) == 4 && quaternions.size(0) == scales.size(0),
              "covariance_from_scale_rotation: quaternions must be [N, 4]");
  const at::Tensor q = quaternions / quaternions.norm(2, {1}, true);
  const at::Tensor w = q.select(1, 0), x = q.select(1, 1), y = q.select(1, 2), z = q.select(1, 3);
  const at::Tensor rotation =
      at::stack({1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
                 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),  //
                 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
                1)
          .view({-1, 3, 3});
  const at::Tensor scaled = rotation * scales.unsqueeze(1);  // R diag(s)
  const at::Tensor cov = at::matmul(scaled, scaled.transpose(1, 2));
  return at::stack({cov.select(2, 0).select(1, 0), cov.select(2, 1).select(1, 0), cov.select(2, 2).select(1, 0),
                    cov.select(2, 1).select(1, 1), cov.select(2, 2).select(1, 1), cov.select(2, 2).select(1, 2)},
                   1);
}

}  // namespace tega::splat
