// shaded_sh: the checks, the autograd Function, the CPU loops and the
// dispatch to the CUDA kernels. As tensor ops (scale, add, concatenate, and
// their gradients) it took ~5 ms of copies a step at 4M Gaussians on an H200.

#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include "shaded_sh_glue.h"
#include "shaded_sh_math.h"
#include "tega/avatar/device_dispatch.h"
#include "tega/trainer/spherical_harmonics.h"

namespace tega::trainer {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

constexpr double kHalfOverC0 = 0.5 / kShConstant;

class ShadedShFunction : public torch::autograd::Function<ShadedShFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& dc, const at::Tensor& rest,
                               const at::Tensor& shading, int64_t used) {
    ctx->save_for_backward({dc, rest, shading});
    ctx->saved_data["used"] = used;
    const int64_t n = dc.size(0), stored = rest.size(1);
    at::Tensor out = at::empty({n, used, 3}, dc.options());
    if (use_cuda_kernels(dc, "shaded_sh")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      shading_fold::forward_cuda(dc, rest, shading, kHalfOverC0, out);
#endif
    } else {
      AT_DISPATCH_FLOATING_TYPES(dc.scalar_type(), "shaded_sh", [&] {
        const scalar_t *d = dc.data_ptr<scalar_t>(), *r = rest.data_ptr<scalar_t>(), *s = shading.data_ptr<scalar_t>();
        scalar_t* o = out.data_ptr<scalar_t>();
        at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
          for (int64_t i = begin; i < end; ++i)
            for (int k = 0; k < 3 * used; ++k)
              o[3 * used * i + k] =
                  shading_fold::forward_element(d + 3 * i, r + 3 * stored * i, s[i], scalar_t(kHalfOverC0), k);
        });
      });
    }
    return {out};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor &dc = saved[0], &rest = saved[1], &shading = saved[2];
    const int64_t used = ctx->saved_data["used"].toInt(), n = dc.size(0), stored = rest.size(1);
    const at::Tensor grad_out = grads[0].contiguous();
    at::Tensor grad_dc = at::empty_like(dc), grad_rest = at::empty_like(rest), grad_shading = at::empty_like(shading);
    if (use_cuda_kernels(dc, "shaded_sh")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      shading_fold::backward_cuda(dc, rest, shading, kHalfOverC0, grad_out, grad_dc, grad_rest, grad_shading);
#endif
    } else {
      AT_DISPATCH_FLOATING_TYPES(dc.scalar_type(), "shaded_sh_backward", [&] {
        const scalar_t *d = dc.data_ptr<scalar_t>(), *r = rest.data_ptr<scalar_t>(), *s = shading.data_ptr<scalar_t>(),
                       *g = grad_out.data_ptr<scalar_t>();
        scalar_t *gd = grad_dc.data_ptr<scalar_t>(), *gr = grad_rest.data_ptr<scalar_t>(),
                 *gs = grad_shading.data_ptr<scalar_t>();
        at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
          for (int64_t i = begin; i < end; ++i) {
            scalar_t grad_s = 0;
            for (int k = 0; k < 3 * (stored + 1); ++k)
              grad_s += shading_fold::backward_element(d + 3 * i, r + 3 * stored * i, s[i], scalar_t(kHalfOverC0),
                                                       int(used), k, g + 3 * used * i,
                                                       k < 3 ? gd[3 * i + k] : gr[3 * stored * i + k - 3]);
            gs[i] = grad_s;
          }
        });
      });
    }
    return {grad_dc, grad_rest, grad_shading, at::Tensor()};
  }
};

}  // namespace

at::Tensor shaded_sh(const at::Tensor& sh_dc, const at::Tensor& sh_rest, const at::Tensor& shading, int used) {
  TORCH_CHECK(sh_dc.dim() == 3 && sh_dc.size(1) == 1 && sh_dc.size(2) == 3, "shaded_sh: sh_dc must be [N,1,3]");
  TORCH_CHECK(sh_rest.dim() == 3 && sh_rest.size(0) == sh_dc.size(0) && sh_rest.size(2) == 3,
              "shaded_sh: sh_rest must be [N,K-1,3] with sh_dc's N");
  TORCH_CHECK(shading.numel() == sh_dc.size(0), "shaded_sh: one shading value per Gaussian");
  TORCH_CHECK(used >= 1 && used - 1 <= sh_rest.size(1), "shaded_sh: ", used, " coefficients used, ",
              sh_rest.size(1) + 1, " stored");
  TORCH_CHECK(sh_rest.scalar_type() == sh_dc.scalar_type() && shading.scalar_type() == sh_dc.scalar_type() &&
                  sh_rest.device() == sh_dc.device() && shading.device() == sh_dc.device(),
              "shaded_sh: one dtype and device");
  return ShadedShFunction::apply(sh_dc.contiguous(), sh_rest.contiguous(), shading.reshape({-1}).contiguous(),
                                 int64_t(used))[0];
}

}  // namespace tega::trainer
