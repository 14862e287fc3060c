// Torch glue of fused_uvd_to_world's CUDA kernels: outputs from the caching
// allocator, kernels on the current stream.

#include "fused_uvd_map_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "fused_uvd_map_kernels.h"

namespace tega::uvd::fused_uvd_map {

std::pair<at::Tensor, at::Tensor> forward_cuda(const at::Tensor& uvd, const at::Tensor& uv,
                                               const at::Tensor& triangle, const SurfaceTensors& surface) {
  const c10::cuda::CUDAGuard guard(uvd.device());
  const int64_t n = uvd.size(0);
  at::Tensor xyz = at::empty({n, 3}, uvd.options()), jacobian = at::empty({n, 3, 3}, uvd.options());
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "uvd_to_world", [&] {
    cuda::forward(n, pointers<scalar_t>(surface), triangle.data_ptr<int64_t>(), uv.data_ptr<scalar_t>(),
                  uvd.data_ptr<scalar_t>(), xyz.data_ptr<scalar_t>(), jacobian.data_ptr<scalar_t>(),
                  at::cuda::getCurrentCUDAStream());
  });
  return {xyz, jacobian};
}

at::Tensor backward_cuda(const at::Tensor& uvd, const at::Tensor& uv, const at::Tensor& triangle,
                         const SurfaceTensors& surface, const at::Tensor& grad_xyz, const at::Tensor& grad_jacobian) {
  const c10::cuda::CUDAGuard guard(uvd.device());
  at::Tensor grad_uvd = at::empty_like(uvd);
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "uvd_to_world_backward", [&] {
    cuda::backward(uvd.size(0), pointers<scalar_t>(surface), triangle.data_ptr<int64_t>(), uv.data_ptr<scalar_t>(),
                   uvd.data_ptr<scalar_t>(), grad_xyz.defined() ? grad_xyz.data_ptr<scalar_t>() : nullptr,
                   grad_jacobian.defined() ? grad_jacobian.data_ptr<scalar_t>() : nullptr,
                   grad_uvd.data_ptr<scalar_t>(), at::cuda::getCurrentCUDAStream());
  });
  return grad_uvd;
}

}  // namespace tega::uvd::fused_uvd_map

#endif
