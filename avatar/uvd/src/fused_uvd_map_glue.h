#pragma once
// The CPU and CUDA implementations behind fused_uvd_to_world's autograd
// Function (fused_uvd_map.cpp). uvd [N,3], uv [N,2] and triangle [N] int64
// are contiguous, as are the surface's tensors; one floating dtype.

#include <ATen/core/Tensor.h>

#include <utility>

#include "fused_uvd_map_math.h"

namespace tega::uvd::fused_uvd_map {

struct SurfaceTensors {
  at::Tensor faces, vertices, normals, corners, inverse, gradient;
};

template <typename T>
Surface<T> pointers(const SurfaceTensors& s) {
  return {s.faces.data_ptr<int64_t>(), s.vertices.data_ptr<T>(), s.normals.data_ptr<T>(),
          s.corners.data_ptr<T>(),     s.inverse.data_ptr<T>(),  s.gradient.data_ptr<T>()};
}

// Returns (xyz [N,3], jacobian [N,3,3]).
std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                                              const SurfaceTensors& surface);
// grad_xyz and grad_jacobian may be undefined; returns grad_uvd [N,3].
at::Tensor backward_cpu(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                        const SurfaceTensors& surface, const at::Tensor& grad_xyz, const at::Tensor& grad_jacobian);
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& uvd, const at::Tensor& uv,
                                               const at::Tensor& triangle, const SurfaceTensors& surface);
at::Tensor backward_cuda(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                         const SurfaceTensors& surface, const at::Tensor& grad_xyz, const at::Tensor& grad_jacobian);
#endif

}  // namespace tega::uvd::fused_uvd_map
