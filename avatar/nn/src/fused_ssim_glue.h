#pragma once
// Between fused_ssim.cpp (checks and the autograd Function) and the CPU and
// CUDA implementations. Images arrive as contiguous [planes, H, W] tensors
// of one dtype on one device.

#include <ATen/core/Tensor.h>

namespace tega::nn::fused_ssim_glue {

struct Forward {
  at::Tensor value;   // 0-dim mean SSIM, the images' dtype
  at::Tensor d_maps;  // [3, planes, H, W]: ∂m/∂μa, ∂m/∂E[a²], ∂m/∂E[ab] (ssim_math.h); only when asked for
};

Forward forward_cpu(const at::Tensor& a, const at::Tensor& b, bool with_gradient);
// ∂(grad_output · mean SSIM)/∂a.
at::Tensor backward_cpu(const at::Tensor& a, const at::Tensor& b, const at::Tensor& d_maps,
                        const at::Tensor& grad_output);

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
Forward forward_cuda(const at::Tensor& a, const at::Tensor& b, bool with_gradient);
at::Tensor backward_cuda(const at::Tensor& a, const at::Tensor& b, const at::Tensor& d_maps,
                         const at::Tensor& grad_output);
#endif

}  // namespace tega::nn::fused_ssim_glue
