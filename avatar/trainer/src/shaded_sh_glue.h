#pragma once
// The CUDA side of shaded_sh (shaded_sh.cpp runs the CPU loops itself):
// contiguous tensors on one GPU, one floating dtype; dc [N,1,3], rest
// [N,stored,3], shading [N], out and grad_out [N,used,3].

#include <ATen/core/Tensor.h>

namespace tega::trainer::shading_fold {

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
void forward_cuda(const at::Tensor& dc, const at::Tensor& rest, const at::Tensor& shading, double half_over_c0,
                  const at::Tensor& out);
void backward_cuda(const at::Tensor& dc, const at::Tensor& rest, const at::Tensor& shading, double half_over_c0,
                   const at::Tensor& grad_out, const at::Tensor& grad_dc, const at::Tensor& grad_rest,
                   const at::Tensor& grad_shading);
#endif

}  // namespace tega::trainer::shading_fold
