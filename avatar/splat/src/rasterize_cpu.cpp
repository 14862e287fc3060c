// Torch glue of the CPU pipeline (float and double).

#include "cpu_rasterizer.h"
#include "raster_glue.h"

namespace tega::splat::glue {
namespace {

constexpr int64_t kSplatWidth = sizeof(Splat2D<float>) / sizeof(float);
static_assert(sizeof(Splat2D<double>) == kSplatWidth * sizeof(double));

template <typename T>
Splat2D<T>* splat_ptr(const at::Tensor& t) {
  return reinterpret_cast<Splat2D<T>*>(t.data_ptr<T>());
}

template <typename T>
ForwardTensors forward(const RasterTensors& t, const CallConfig& config) {
  const auto cameras = camera_params<T>(config.cameras);
  const RasterInputs<T> in = make_inputs<T>(t, config, cameras.data());
  const auto opts = t.means.options();
  const auto int_opts = opts.dtype(at::kInt);
  const int64_t c = in.num_cameras, n = in.num_gaussians;
  const ImageGeometry& g = in.geometry;

  ForwardTensors f;
  f.splats = at::empty({c * n, kSplatWidth}, opts);
  f.radii = at::empty({c, n}, int_opts);
  f.color_jacobians = empty_color_jacobians(in, opts);
  at::Tensor rects = at::empty({c * n, 4}, int_opts);
  const ProjectedBuffers<T> projected{splat_ptr<T>(f.splats), reinterpret_cast<TileRect*>(rects.data_ptr<int32_t>()),
                                      f.radii.data_ptr<int32_t>(), color_jacobian_ptr<T>(f.color_jacobians)};
  cpu::project(in, projected);

  f.ranges = at::empty({in.num_tiles(), 2}, int_opts);
  std::vector<int32_t> ids = cpu::bin(in, projected, f.ranges.data_ptr<int32_t>());
  f.gaussian_ids = at::empty({int64_t(ids.size())}, int_opts);
  std::copy(ids.begin(), ids.end(), f.gaussian_ids.data_ptr<int32_t>());

  f.rgb = at::empty({c, g.height, g.width, 3}, opts);
  f.alpha = at::empty({c, g.height, g.width}, opts);
  f.depth = at::empty_like(f.alpha);
  f.final_transmittance = at::empty_like(f.alpha);
  f.last = at::empty({c, g.height, g.width}, int_opts);
  const TileBins bins{f.ranges.data_ptr<int32_t>(), f.gaussian_ids.data_ptr<int32_t>(), f.gaussian_ids.numel()};
  cpu::render_forward(in, splat_ptr<T>(f.splats), bins,
                      ImageBuffers<T>{f.rgb.data_ptr<T>(), f.alpha.data_ptr<T>(), f.depth.data_ptr<T>(),
                                      f.final_transmittance.data_ptr<T>(), f.last.data_ptr<int32_t>()});
  return f;
}

template <typename T>
InputGradTensors backward(const RasterTensors& t, const CallConfig& config, const ForwardTensors& saved,
                          const ImageGradTensors& grads, const MeanGradientStats* stats) {
  const auto cameras = camera_params<T>(config.cameras);
  const RasterInputs<T> in = make_inputs<T>(t, config, cameras.data());
  const TileBins bins{saved.ranges.data_ptr<int32_t>(), saved.gaussian_ids.data_ptr<int32_t>(),
                      saved.gaussian_ids.numel()};
  const ImageBuffers<T> image{nullptr, nullptr, saved.depth.data_ptr<T>(), saved.final_transmittance.data_ptr<T>(),
                              saved.last.data_ptr<int32_t>()};
  at::Tensor splat_grads = at::empty_like(saved.splats);
  cpu::render_backward(in, splat_ptr<T>(saved.splats), bins, image,
                       ImageGradients<T>{grads.rgb.data_ptr<T>(), grads.alpha.data_ptr<T>(),
                                         grads.depth.defined() ? grads.depth.data_ptr<T>() : nullptr},
                       splat_ptr<T>(splat_grads));

  // d rgb / d background = final transmittance, per pixel.
  InputGradTensors out{at::empty_like(t.means), at::empty_like(t.covariances), at::empty_like(t.colors),
                       at::empty_like(t.opacities),
                       (grads.rgb * saved.final_transmittance.unsqueeze(-1)).sum({0, 1, 2})};
  InputGradients<T> dst{out.means.data_ptr<T>(), out.covariances.data_ptr<T>(), out.colors.data_ptr<T>(),
                        out.opacities.data_ptr<T>()};
  if (stats) {
    dst.mean2d_grad_norm_sum = stats->grad_norm_sum.data_ptr<T>();
    dst.visible_count = stats->visible_count.data_ptr<int32_t>();
  }
  cpu::project_backward(in, saved.radii.data_ptr<int32_t>(), splat_ptr<T>(splat_grads),
                        color_jacobian_ptr<T>(saved.color_jacobians), dst);
  return out;
}

}  // namespace

ForwardTensors forward_cpu(const RasterTensors& t, const CallConfig& config) {
  return t.means.scalar_type() == at::kDouble ? forward<double>(t, config) : forward<float>(t, config);
}

InputGradTensors backward_cpu(const RasterTensors& t, const CallConfig& config, const ForwardTensors& saved,
                              const ImageGradTensors& grads, const MeanGradientStats* stats) {
  return t.means.scalar_type() == at::kDouble ? backward<double>(t, config, saved, grads, stats)
                                              : backward<float>(t, config, saved, grads, stats);
}

}  // namespace tega::splat::glue
