// fused_ssim(): input checks, the autograd Function and the dispatch between
// the CPU and CUDA implementations.

#include "tega/nn/fused_ssim.h"

#include "fused_ssim_glue.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <torch/csrc/autograd/custom_function.h>

#include "tega/avatar/device_dispatch.h"

namespace tega::nn {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

fused_ssim_glue::Forward run_forward(const at::Tensor& a, const at::Tensor& b, bool with_gradient) {
  if (use_cuda_kernels(a, "fused_ssim")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return fused_ssim_glue::forward_cuda(a, b, with_gradient);
#endif
  }
  return fused_ssim_glue::forward_cpu(a, b, with_gradient);
}

at::Tensor run_backward(const at::Tensor& a, const at::Tensor& b, const at::Tensor& d_maps,
                        const at::Tensor& grad_output) {
  if (use_cuda_kernels(a, "fused_ssim")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return fused_ssim_glue::backward_cuda(a, b, d_maps, grad_output);
#endif
  }
  return fused_ssim_glue::backward_cpu(a, b, d_maps, grad_output);
}

// Inputs are contiguous [planes, H, W]. The forward writes the SSIM map's
// partial derivatives only when a gradient will be asked for.
class FusedSsimFunction : public torch::autograd::Function<FusedSsimFunction> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& a, const at::Tensor& b, bool with_gradient) {
    fused_ssim_glue::Forward f = run_forward(a, b, with_gradient);
    if (with_gradient) ctx->save_for_backward({a, b, f.d_maps});
    return f.value;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grad_outputs) {
    const variable_list saved = ctx->get_saved_variables();
    return {run_backward(saved[0], saved[1], saved[2], grad_outputs[0]), at::Tensor(), at::Tensor()};
  }
};

}  // namespace

at::Tensor fused_ssim(const at::Tensor& rendered, const at::Tensor& target) {
  TORCH_CHECK(rendered.defined() && target.defined(), "fused_ssim: undefined tensor");
  TORCH_CHECK(rendered.sizes() == target.sizes(), "fused_ssim: sizes differ, ", rendered.sizes(), " vs ",
              target.sizes());
  TORCH_CHECK(rendered.dim() == 3 || rendered.dim() == 4, "fused_ssim: images must be [C,H,W] or [B,C,H,W], got ",
              rendered.sizes());
  TORCH_CHECK(rendered.numel() > 0, "fused_ssim: empty images");
  TORCH_CHECK(rendered.scalar_type() == target.scalar_type() && rendered.device() == target.device(),
              "fused_ssim: both images must have one dtype and device");
  TORCH_CHECK(rendered.scalar_type() == at::kFloat || (rendered.scalar_type() == at::kDouble && !rendered.is_cuda()),
              "fused_ssim: images must be float32 (or float64 on the CPU)");
  const bool grad_mode = at::GradMode::is_enabled();
  TORCH_CHECK(!(grad_mode && target.requires_grad()),
              "fused_ssim: the target gets no gradient; detach it (or use ssim())");
  const int64_t height = rendered.size(-2), width = rendered.size(-1);
  const at::Tensor a = rendered.reshape({-1, height, width}).contiguous();
  const at::Tensor b = target.reshape({-1, height, width}).contiguous();
  return FusedSsimFunction::apply(a, b, grad_mode && rendered.requires_grad());
}

}  // namespace tega::nn
