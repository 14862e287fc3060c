// Torch glue of the CUDA pipeline: buffers come from the caching allocator
// and kernels run on the current stream.

#include "raster_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include "cuda_rasterizer.h"

#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include <cstring>

namespace tega::splat::glue {
namespace {

constexpr int64_t kSplatWidth = sizeof(Splat2D<float>) / sizeof(float);

// Temporaries as byte tensors: they return to the caching allocator when
// the workspace goes out of scope.
class TorchWorkspace final : public cuda::Workspace {
 public:
  explicit TorchWorkspace(at::Device device) : options_(at::TensorOptions().dtype(at::kByte).device(device)) {}
  void* allocate(std::size_t bytes) override {
    buffers_.push_back(at::empty({int64_t(bytes)}, options_));
    return buffers_.back().data_ptr();
  }

 private:
  at::TensorOptions options_;
  std::vector<at::Tensor> buffers_;
};

Splat2D<float>* splat_ptr(const at::Tensor& t) { return reinterpret_cast<Splat2D<float>*>(t.data_ptr<float>()); }

// Camera parameters copied to the device through pinned memory, so the copy
// does not wait for the work already queued on the stream.
at::Tensor device_cameras(const CallConfig& config, at::Device device) {
  const auto params = camera_params<float>(config.cameras);
  const int64_t width = sizeof(CameraParams<float>) / sizeof(float);
  at::Tensor host =
      at::empty({int64_t(params.size()), width}, at::TensorOptions().dtype(at::kFloat).pinned_memory(true));
  std::memcpy(host.data_ptr<float>(), params.data(), params.size() * sizeof(CameraParams<float>));
  return host.to(at::TensorOptions().device(device), /*non_blocking=*/true);
}

const CameraParams<float>* camera_ptr(const at::Tensor& t) {
  return reinterpret_cast<const CameraParams<float>*>(t.data_ptr<float>());
}

}  // namespace

ForwardTensors forward_cuda(const RasterTensors& t, const CallConfig& config) {
  const c10::cuda::CUDAGuard guard(t.means.device());
  const cudaStream_t stream = at::cuda::getCurrentCUDAStream();
  const at::Tensor cameras = device_cameras(config, t.means.device());
  const RasterInputs<float> in = make_inputs<float>(t, config, camera_ptr(cameras));
  const auto opts = t.means.options();
  const auto int_opts = opts.dtype(at::kInt);
  const int64_t c = in.num_cameras, n = in.num_gaussians;
  const ImageGeometry& g = in.geometry;

  ForwardTensors f;
  f.splats = at::empty({c * n, kSplatWidth}, opts);
  f.radii = at::empty({c, n}, int_opts);
  TorchWorkspace workspace(t.means.device());
  f.color_jacobians = empty_color_jacobians(in, opts);
  at::Tensor rects = at::empty({c * n, 4}, int_opts);
  const ProjectedBuffers<float> projected{splat_ptr(f.splats), reinterpret_cast<TileRect*>(rects.data_ptr<int32_t>()),
                                          f.radii.data_ptr<int32_t>(), color_jacobian_ptr<float>(f.color_jacobians)};
  const cuda::DepthKeys depth_keys = cuda::project(in, projected, workspace, stream);
  const cuda::DepthOrder order = cuda::sort_by_depth(in, projected, depth_keys, workspace, stream);
  f.ranges = at::empty({in.num_tiles(), 2}, int_opts);
  f.gaussian_ids = at::empty({order.total}, int_opts);
  cuda::bin(in, projected, order, f.gaussian_ids.data_ptr<int32_t>(), f.ranges.data_ptr<int32_t>(), workspace, stream);

  f.rgb = at::empty({c, g.height, g.width, 3}, opts);
  f.alpha = at::empty({c, g.height, g.width}, opts);
  f.depth = at::empty_like(f.alpha);
  f.final_transmittance = at::empty_like(f.alpha);
  f.last = at::empty({c, g.height, g.width}, int_opts);
  const TileBins bins{f.ranges.data_ptr<int32_t>(), f.gaussian_ids.data_ptr<int32_t>(), order.total};
  cuda::render_forward(in, splat_ptr(f.splats), bins,
                       ImageBuffers<float>{f.rgb.data_ptr<float>(), f.alpha.data_ptr<float>(), f.depth.data_ptr<float>(),
                                           f.final_transmittance.data_ptr<float>(), f.last.data_ptr<int32_t>()},
                       stream);
  return f;
}

InputGradTensors backward_cuda(const RasterTensors& t, const CallConfig& config, const ForwardTensors& saved,
                               const ImageGradTensors& grads, const MeanGradientStats* stats) {
  const c10::cuda::CUDAGuard guard(t.means.device());
  const cudaStream_t stream = at::cuda::getCurrentCUDAStream();
  const at::Tensor cameras = device_cameras(config, t.means.device());
  const RasterInputs<float> in = make_inputs<float>(t, config, camera_ptr(cameras));
  const TileBins bins{saved.ranges.data_ptr<int32_t>(), saved.gaussian_ids.data_ptr<int32_t>(),
                      saved.gaussian_ids.numel()};
  const ImageBuffers<float> image{nullptr, nullptr, saved.depth.data_ptr<float>(),
                                  saved.final_transmittance.data_ptr<float>(), saved.last.data_ptr<int32_t>()};
  at::Tensor splat_grads = at::zeros_like(saved.splats);
  InputGradTensors out{at::empty_like(t.means), at::empty_like(t.covariances), at::empty_like(t.colors),
                       at::empty_like(t.opacities), at::zeros_like(t.background)};
  cuda::render_backward(in, splat_ptr(saved.splats), bins, image,
                        ImageGradients<float>{grads.rgb.data_ptr<float>(), grads.alpha.data_ptr<float>(),
                                              grads.depth.defined() ? grads.depth.data_ptr<float>() : nullptr},
                        splat_ptr(splat_grads), stream);
  cuda::background_backward(in, saved.final_transmittance.data_ptr<float>(), grads.rgb.data_ptr<float>(),
                            out.background.data_ptr<float>(), stream);

  InputGradients<float> dst{out.means.data_ptr<float>(), out.covariances.data_ptr<float>(),
                            out.colors.data_ptr<float>(), out.opacities.data_ptr<float>()};
  if (stats) {
    dst.mean2d_grad_norm_sum = stats->grad_norm_sum.data_ptr<float>();
    dst.visible_count = stats->visible_count.data_ptr<int32_t>();
  }
  cuda::project_backward(in, saved.radii.data_ptr<int32_t>(), splat_ptr(splat_grads),
                         color_jacobian_ptr<float>(saved.color_jacobians), dst, stream);
  return out;
}

}  // namespace tega::splat::glue

#endif
