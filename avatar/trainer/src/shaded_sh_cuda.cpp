// Torch glue of shaded_sh's CUDA kernels: the current stream.

#include "shaded_sh_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/Dispatch.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "shaded_sh_kernels.h"

namespace tega::trainer::shading_fold {

void forward_cuda(const at::Tensor& dc, const at::Tensor& rest, const at::Tensor& shading, double half_over_c0,
                  const at::Tensor& out) {
  const c10::cuda::CUDAGuard guard(dc.device());
  AT_DISPATCH_FLOATING_TYPES(dc.scalar_type(), "shaded_sh", [&] {
    cuda::forward<scalar_t>(dc.size(0), int(out.size(1)), int(rest.size(1)), scalar_t(half_over_c0),
                            dc.data_ptr<scalar_t>(), rest.data_ptr<scalar_t>(), shading.data_ptr<scalar_t>(),
                            out.data_ptr<scalar_t>(), at::cuda::getCurrentCUDAStream());
  });
}

void backward_cuda(const at::Tensor& dc, const at::Tensor& rest, const at::Tensor& shading, double half_over_c0,
                   const at::Tensor& grad_out, const at::Tensor& grad_dc, const at::Tensor& grad_rest,
                   const at::Tensor& grad_shading) {
  const c10::cuda::CUDAGuard guard(dc.device());
  AT_DISPATCH_FLOATING_TYPES(dc.scalar_type(), "shaded_sh_backward", [&] {
    cuda::backward<scalar_t>(dc.size(0), int(grad_out.size(1)), int(rest.size(1)), scalar_t(half_over_c0),
                             dc.data_ptr<scalar_t>(), rest.data_ptr<scalar_t>(), shading.data_ptr<scalar_t>(),
                             grad_out.data_ptr<scalar_t>(), grad_dc.data_ptr<scalar_t>(),
                             grad_rest.data_ptr<scalar_t>(), grad_shading.data_ptr<scalar_t>(),
                             at::cuda::getCurrentCUDAStream());
  });
}

}  // namespace tega::trainer::shading_fold

#endif
