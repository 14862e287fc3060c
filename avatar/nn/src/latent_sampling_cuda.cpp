// Torch glue of sample_latent's CUDA kernels: outputs from the caching
// allocator, kernels on the current stream.

#include "latent_sampling_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "latent_sampling_kernels.h"

namespace tega::nn::latent_sampling {
namespace {

cuda::Shape shape_of(const at::Tensor& latent, const at::Tensor& uv) {
  return {uv.size(0), latent.size(2), latent.size(0), latent.size(1)};
}

}  // namespace

at::Tensor forward_cuda(const at::Tensor& latent, const at::Tensor& uv) {
  const c10::cuda::CUDAGuard guard(latent.device());
  at::Tensor sampled = at::empty({uv.size(0), latent.size(2)}, latent.options());
  cuda::forward(shape_of(latent, uv), latent.data_ptr<float>(), uv.data_ptr<float>(), sampled.data_ptr<float>(),
                at::cuda::getCurrentCUDAStream());
  return sampled;
}

std::pair<at::Tensor, at::Tensor> backward_cuda(const at::Tensor& latent, const at::Tensor& uv,
                                                const at::Tensor& grad_sampled) {
  const c10::cuda::CUDAGuard guard(latent.device());
  at::Tensor grad_latent = at::zeros_like(latent), grad_uv = at::zeros_like(uv);
  cuda::backward(shape_of(latent, uv), latent.data_ptr<float>(), uv.data_ptr<float>(), grad_sampled.data_ptr<float>(),
                 grad_latent.data_ptr<float>(), grad_uv.data_ptr<float>(), at::cuda::getCurrentCUDAStream());
  return {grad_latent, grad_uv};
}

}  // namespace tega::nn::latent_sampling

#endif
