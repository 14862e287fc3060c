// silu_with_tangents: checks, the autograd Function, the CPU loops and the
// dispatch to the CUDA kernels.

#include "tega/nn/silu_tangents.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include "silu_tangents_glue.h"
#include "silu_tangents_math.h"
#include "tega/avatar/device_dispatch.h"

namespace tega::nn {
namespace silu_tangents {

std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& pre, const at::Tensor& tangents) {
  at::Tensor value = at::empty_like(pre), out = at::empty_like(tangents);
  const int64_t width = pre.size(1);
  AT_DISPATCH_FLOATING_TYPES(pre.scalar_type(), "silu_with_tangents", [&] {
    const scalar_t* x = pre.data_ptr<scalar_t>();
    const scalar_t* t = tangents.data_ptr<scalar_t>();
    scalar_t* h = value.data_ptr<scalar_t>();
    scalar_t* u = out.data_ptr<scalar_t>();
    at::parallel_for(0, pre.size(0), 1024, [&](int64_t begin, int64_t end) {
      for (int64_t row = begin; row < end; ++row) {
        for (int64_t j = 0; j < width; ++j) {
          const int64_t i = row * width + j, k = row * kAxes * width + j;
          forward_element(x[i], t + k, width, h + i, u + k);
        }
      }
    });
  });
  return {value, out};
}

std::pair<at::Tensor, at::Tensor> backward_cpu(const at::Tensor& pre, const at::Tensor& tangents,
                                               const at::Tensor& grad_value, const at::Tensor& grad_tangents) {
  at::Tensor grad_pre = at::empty_like(pre), grad_t = at::empty_like(tangents);
  const int64_t width = pre.size(1);
  AT_DISPATCH_FLOATING_TYPES(pre.scalar_type(), "silu_with_tangents_backward", [&] {
    const scalar_t* x = pre.data_ptr<scalar_t>();
    const scalar_t* t = tangents.data_ptr<scalar_t>();
    const scalar_t* gh = grad_value.defined() ? grad_value.data_ptr<scalar_t>() : nullptr;
    const scalar_t* gu = grad_tangents.data_ptr<scalar_t>();
    scalar_t* gx = grad_pre.data_ptr<scalar_t>();
    scalar_t* gt = grad_t.data_ptr<scalar_t>();
    at::parallel_for(0, pre.size(0), 1024, [&](int64_t begin, int64_t end) {
      for (int64_t row = begin; row < end; ++row) {
        for (int64_t j = 0; j < width; ++j) {
          const int64_t i = row * width + j, k = row * kAxes * width + j;
          backward_element(x[i], t + k, gh ? gh + i : nullptr, gu + k, width, gx + i, gt + k);
        }
      }
    });
  });
  return {grad_pre, grad_t};
}

}  // namespace silu_tangents

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

std::pair<at::Tensor, at::Tensor> run_forward(const at::Tensor& pre, const at::Tensor& tangents) {
  if (use_cuda_kernels(pre, "silu_with_tangents")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return silu_tangents::forward_cuda(pre, tangents);
#endif
  }
  return silu_tangents::forward_cpu(pre, tangents);
}

std::pair<at::Tensor, at::Tensor> run_backward(const at::Tensor& pre, const at::Tensor& tangents,
                                               const at::Tensor& grad_value, const at::Tensor& grad_tangents) {
  if (use_cuda_kernels(pre, "silu_with_tangents")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
    return silu_tangents::backward_cuda(pre, tangents, grad_value, grad_tangents);
#endif
  }
  return silu_tangents::backward_cpu(pre, tangents, grad_value, grad_tangents);
}

class SiluWithTangentsFunction : public torch::autograd::Function<SiluWithTangentsFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& pre, const at::Tensor& tangents) {
    ctx->save_for_backward({pre, tangents});
    const auto [value, out] = run_forward(pre, tangents);
    return {value, out};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor& pre = saved[0];
    const at::Tensor& tangents = saved[1];
    const at::Tensor grad_value = grads[0].defined() ? grads[0].contiguous() : at::Tensor();
    // Without a gradient on the tangents, this is plain SiLU's backward.
    if (!grads[1].defined()) {
      if (!grad_value.defined()) return {at::Tensor(), at::Tensor()};
      return {at::silu_backward(grad_value, pre), at::Tensor()};
    }
    const at::Tensor grad_tangents = grads[1].contiguous();
    const auto [grad_pre, grad_t] = run_backward(pre, tangents, grad_value, grad_tangents);
    return {grad_pre, grad_t};
  }
};

}  // namespace

SiluWithTangents silu_with_tangents(const at::Tensor& pre, const at::Tensor& tangents) {
  TORCH_CHECK(pre.dim() == 2, "silu_with_tangents: pre must be [N,H], got ", pre.sizes());
  TORCH_CHECK(tangents.dim() == 3 && tangents.size(0) == pre.size(0) && tangents.size(1) == silu_tangents::kAxes &&
                  tangents.size(2) == pre.size(1),
              "silu_with_tangents: tangents must be [N,3,H] for pre ", pre.sizes(), ", got ", tangents.sizes());
  TORCH_CHECK(pre.scalar_type() == tangents.scalar_type() && pre.device() == tangents.device(),
              "silu_with_tangents: pre and tangents must share dtype and device");
  const at::ScalarType type = pre.scalar_type();
  TORCH_CHECK(type == at::kFloat || (pre.is_cuda() ? type == at::kBFloat16 : type == at::kDouble),
              "silu_with_tangents: CUDA takes float32 or bfloat16, the CPU float32 or float64; got ", type, " on ",
              pre.device());
  const variable_list out = SiluWithTangentsFunction::apply(pre.contiguous(), tangents.contiguous());
  return {out[0], out[1]};
}

}  // namespace tega::nn
