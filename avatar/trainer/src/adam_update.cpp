#include "adam_update.h"

#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>

#include "tega/avatar/device_dispatch.h"

namespace tega::trainer::adam_update {

void step(const at::Tensor& param, const at::Tensor& grad, const at::Tensor& first_moment,
          const at::Tensor& second_moment, const at::Tensor& column_scale, const Constants<double>& constants) {
  for (const at::Tensor* t : {&grad, &first_moment, &second_moment})
    TORCH_CHECK(t->sizes() == param.sizes() && t->scalar_type() == param.scalar_type() &&
                    t->device() == param.device() && t->is_contiguous(),
                "adam: parameter, gradient and moments must share shape, dtype and device, contiguous");
  TORCH_CHECK(param.is_contiguous(), "adam: the parameter must be contiguous");
  const int64_t columns = param.dim() > 0 ? param.size(-1) : 1;
  TORCH_CHECK(!column_scale.defined() || (column_scale.numel() == columns &&
                                          column_scale.scalar_type() == param.scalar_type() &&
                                          column_scale.device() == param.device() && column_scale.is_contiguous()),
              "adam: the step scale must hold one factor per entry of the parameter's last dimension");
  // The parameter changes in place behind autograd's back: bump its version
  // as an in-place op would, so a graph that saved it refuses to use it.
  param.unsafeGetTensorImpl()->bump_version();
  if (use_cuda_kernels(param, "adam")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    step_cuda(param, grad, first_moment, second_moment, column_scale, constants);
    return;
#endif
  }
  AT_DISPATCH_FLOATING_TYPES(param.scalar_type(), "adam_step", [&] {
    const Constants<scalar_t> c = constants_as<scalar_t>(constants);
    scalar_t* p = param.data_ptr<scalar_t>();
    const scalar_t* g = grad.data_ptr<scalar_t>();
    scalar_t* m = first_moment.data_ptr<scalar_t>();
    scalar_t* v = second_moment.data_ptr<scalar_t>();
    const scalar_t* scale = column_scale.defined() ? column_scale.data_ptr<scalar_t>() : nullptr;
    at::parallel_for(0, param.numel(), 1 << 14, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i)
        step_element(p[i], g[i], m[i], v[i], scale ? scale[i % columns] : scalar_t(1), c);
    });
  });
}

}  // namespace tega::trainer::adam_update
