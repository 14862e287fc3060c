#pragma once
// Internal glue between the autograd Function and the two pipelines.

#include <tega/splat/rasterize.h>

#include "pipeline.h"

#include <ATen/ATen.h>

#include <vector>

namespace tega::splat::glue {

struct RasterTensors {
  at::Tensor means, covariances, colors, opacities, background;  // contiguous
};

struct CallConfig {
  std::vector<RasterCamera> cameras;
  RasterSettings settings;
};

// What the forward pass returns and what the backward pass needs.
struct ForwardTensors {
  at::Tensor rgb, alpha, depth;  // depth: expected depth Σ w z / alpha
  at::Tensor radii;              // [C, N] int32
  at::Tensor splats;             // [C * N, 12], Splat2D
  at::Tensor color_jacobians;    // [C * N, 12], ColorJacobian; SH colours only (else undefined)
  at::Tensor final_transmittance, last;
  at::Tensor ranges, gaussian_ids;
};

struct ImageGradTensors {
  at::Tensor rgb, alpha;  // contiguous
  at::Tensor depth;       // contiguous; undefined when the loss does not depend on depth
};

struct InputGradTensors {
  at::Tensor means, covariances, colors, opacities, background;
};

// Fills the scalar-independent part of RasterInputs and the pointers of t.
template <typename T>
RasterInputs<T> make_inputs(const RasterTensors& t, const CallConfig& config,
                            const CameraParams<T>* cameras) {
  const RasterSettings& s = config.settings;
  RasterInputs<T> in;
  in.num_gaussians = t.means.size(0);
  in.num_cameras = int32_t(config.cameras.size());
  in.means = t.means.data_ptr<T>();
  in.covariances = t.covariances.data_ptr<T>();
  in.colors = t.colors.data_ptr<T>();
  in.opacities = t.opacities.data_ptr<T>();
  in.background = t.background.data_ptr<T>();
  const bool sh = t.colors.dim() == 3 && !s.per_camera_rgb;
  in.sh_coefficients = sh ? int32_t(t.colors.size(1)) : 0;
  in.sh_degree = sh ? s.sh_degree : 0;
  in.color_camera_stride = s.per_camera_rgb ? in.num_gaussians * 3 : 0;
  in.cameras = cameras;
  in.geometry = make_geometry(s.width, s.height);
  in.projection = {s.near_plane, s.far_plane, s.antialiased};
  return in;
}

// [C * N, 12] for the ColorJacobians when the colours are SH, else undefined.
template <typename T>
at::Tensor empty_color_jacobians(const RasterInputs<T>& in, const at::TensorOptions& options) {
  static_assert(sizeof(ColorJacobian<T>) == 12 * sizeof(T));
  return in.sh_coefficients > 0 ? at::empty({in.num_projected(), 12}, options) : at::Tensor();
}

template <typename T>
ColorJacobian<T>* color_jacobian_ptr(const at::Tensor& t) {
  return t.defined() ? reinterpret_cast<ColorJacobian<T>*>(t.data_ptr<T>()) : nullptr;
}

template <typename T>
std::vector<CameraParams<T>> camera_params(const std::vector<RasterCamera>& cameras) {
  std::vector<CameraParams<T>> out(cameras.size());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const RasterCamera& cam = cameras[c];
    CameraParams<T>& p = out[c];
    for (int k = 0; k < 9; ++k) p.rotation[k] = T(cam.rotation[k]);
    for (int k = 0; k < 3; ++k) p.translation[k] = T(cam.translation[k]);
    for (int k = 0; k < 3; ++k)  // centre = -Rᵀ t
      p.centre[k] = T(-(cam.rotation[k] * cam.translation[0] + cam.rotation[3 + k] * cam.translation[1] +
                        cam.rotation[6 + k] * cam.translation[2]));
    p.fx = T(cam.fx);
    p.fy = T(cam.fy);
    p.cx = T(cam.cx);
    p.cy = T(cam.cy);
  }
  return out;
}

ForwardTensors forward_cpu(const RasterTensors& t, const CallConfig& config);
InputGradTensors backward_cpu(const RasterTensors& t, const CallConfig& config, const ForwardTensors& saved,
                              const ImageGradTensors& grads, const MeanGradientStats* stats);

// Defined only when built with CUDA kernels and a CUDA libtorch.
ForwardTensors forward_cuda(const RasterTensors& t, const CallConfig& config);
InputGradTensors backward_cuda(const RasterTensors& t, const CallConfig& config, const ForwardTensors& saved,
                               const ImageGradTensors& grads, const MeanGradientStats* stats);

}  // namespace tega::splat::glue
