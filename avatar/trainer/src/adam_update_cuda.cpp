// Torch glue of the fused Adam update's CUDA kernel: the current stream.

#include "adam_update.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/Dispatch.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "adam_update_kernels.h"

namespace tega::trainer::adam_update {

void step_cuda(const at::Tensor& param, const at::Tensor& grad, const at::Tensor& first_moment,
               const at::Tensor& second_moment, const at::Tensor& column_scale, const Constants<double>& constants) {
  const c10::cuda::CUDAGuard guard(param.device());
  AT_DISPATCH_FLOATING_TYPES(param.scalar_type(), "adam_step_cuda", [&] {
    const Constants<scalar_t> c = constants_as<scalar_t>(constants);
    cuda::step<scalar_t>(param.numel(), param.dim() > 0 ? param.size(-1) : 1, param.data_ptr<scalar_t>(),
                         grad.data_ptr<scalar_t>(), first_moment.data_ptr<scalar_t>(),
                         second_moment.data_ptr<scalar_t>(),
                         column_scale.defined() ? column_scale.data_ptr<scalar_t>() : nullptr, c,
                         at::cuda::getCurrentCUDAStream());
  });
}

}  // namespace tega::trainer::adam_update

#endif
