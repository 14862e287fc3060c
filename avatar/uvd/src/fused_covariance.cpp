// world_covariance_packed: checks, the autograd Function, the CPU loops and
// the dispatch to the CUDA kernels.

#include "tega/uvd/fused_covariance.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include "fused_covariance_glue.h"
#include "fused_covariance_math.h"
#include "tega/avatar/device_dispatch.h"

namespace tega::uvd {
namespace fused_covariance {

std::pair<at::Tensor, at::Tensor> forward_cpu(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                              const at::Tensor& log_scale) {
  const int64_t n = jacobian.size(0);
  at::Tensor covariance = at::empty({n, 6}, jacobian.options()), std_per_scale = at::empty({n, 3}, jacobian.options());
  AT_DISPATCH_FLOATING_TYPES(jacobian.scalar_type(), "world_covariance_packed", [&] {
    const scalar_t* j = jacobian.data_ptr<scalar_t>();
    const scalar_t* q = quaternion.data_ptr<scalar_t>();
    const scalar_t* s = log_scale.data_ptr<scalar_t>();
    scalar_t* c = covariance.data_ptr<scalar_t>();
    scalar_t* std = std_per_scale.data_ptr<scalar_t>();
    at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) forward_element(j + 9 * i, q + 4 * i, s + 3 * i, c + 6 * i, std + 3 * i);
    });
  });
  return {covariance, std_per_scale};
}

Gradients backward_cpu(const at::Tensor& jacobian, const at::Tensor& quaternion, const at::Tensor& log_scale,
                       const at::Tensor& grad_covariance) {
  const int64_t n = jacobian.size(0);
  Gradients grad{at::empty_like(jacobian), at::empty_like(quaternion), at::empty_like(log_scale)};
  AT_DISPATCH_FLOATING_TYPES(jacobian.scalar_type(), "world_covariance_packed_backward", [&] {
    const scalar_t* j = jacobian.data_ptr<scalar_t>();
    const scalar_t* q = quaternion.data_ptr<scalar_t>();
    const scalar_t* s = log_scale.data_ptr<scalar_t>();
    const scalar_t* gc = grad_covariance.data_ptr<scalar_t>();
    scalar_t* gj = grad.jacobian.data_ptr<scalar_t>();
    scalar_t* gq = grad.quaternion.data_ptr<scalar_t>();
    scalar_t* gs = grad.log_scale.data_ptr<scalar_t>();
    at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i)
        backward_element(j + 9 * i, q + 4 * i, s + 3 * i, gc + 6 * i, gj + 9 * i, gq + 4 * i, gs + 3 * i);
    });
  });
  return grad;
}

}  // namespace fused_covariance

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

class WorldCovariancePackedFunction : public torch::autograd::Function<WorldCovariancePackedFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& jacobian, const at::Tensor& quaternion,
                               const at::Tensor& log_scale) {
    ctx->save_for_backward({jacobian, quaternion, log_scale});
    ctx->set_materialize_grads(false);  // an unused output's gradient stays undefined, not zeros
    std::pair<at::Tensor, at::Tensor> out;
    if (use_cuda_kernels(jacobian, "world_covariance_packed")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      out = fused_covariance::forward_cuda(jacobian, quaternion, log_scale);
#endif
    } else {
      out = fused_covariance::forward_cpu(jacobian, quaternion, log_scale);
    }
    ctx->mark_non_differentiable({out.second});
    return {out.first, out.second};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    if (!grads[0].defined()) return {at::Tensor(), at::Tensor(), at::Tensor()};
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor grad_covariance = grads[0].contiguous();
    fused_covariance::Gradients g;
    if (use_cuda_kernels(saved[0], "world_covariance_packed")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      g = fused_covariance::backward_cuda(saved[0], saved[1], saved[2], grad_covariance);
#endif
    } else {
      g = fused_covariance::backward_cpu(saved[0], saved[1], saved[2], grad_covariance);
    }
    return {g.jacobian, g.quaternion, g.log_scale};
  }
};

}  // namespace

PackedCovariance world_covariance_packed(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                         const at::Tensor& log_scale) {
  TORCH_CHECK(jacobian.dim() == 3 && jacobian.size(1) == 3 && jacobian.size(2) == 3,
              "world_covariance_packed: jacobian must be [N,3,3], got ", jacobian.sizes());
  TORCH_CHECK(quaternion.dim() == 2 && quaternion.size(0) == jacobian.size(0) && quaternion.size(1) == 4,
              "world_covariance_packed: quaternion must be [N,4] for N = ", jacobian.size(0), ", got ",
              quaternion.sizes());
  TORCH_CHECK(log_scale.dim() == 2 && log_scale.size(0) == jacobian.size(0) && log_scale.size(1) == 3,
              "world_covariance_packed: log_scale must be [N,3] for N = ", jacobian.size(0), ", got ",
              log_scale.sizes());
  for (const at::Tensor* t : {&quaternion, &log_scale})
    TORCH_CHECK(t->scalar_type() == jacobian.scalar_type() && t->device() == jacobian.device(),
                "world_covariance_packed: jacobian, quaternion and log_scale must share dtype and device");
  const variable_list out =
      WorldCovariancePackedFunction::apply(jacobian.contiguous(), quaternion.contiguous(), log_scale.contiguous());
  return {out[0], out[1]};
}

}  // namespace tega::uvd
