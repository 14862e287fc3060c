// Torch glue of the fused SSIM's CUDA kernels: buffers come from the caching
// allocator and the kernels run on the current stream.

#include "fused_ssim_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include "fused_ssim_kernels.h"

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include <limits>

namespace tega::nn::fused_ssim_glue {
namespace {

constexpr int64_t kMaxPlanes = 65535;  // the grid's z

ssim::cuda::Shape shape_of(const at::Tensor& image) {
  TORCH_CHECK(image.size(0) <= kMaxPlanes, "fused_ssim: CUDA takes at most ", kMaxPlanes, " images x channels, got ",
              image.size(0));
  TORCH_CHECK(image.size(1) <= std::numeric_limits<int>::max() && image.size(2) <= std::numeric_limits<int>::max(),
              "fused_ssim: image too large");
  return {image.size(0), int(image.size(1)), int(image.size(2))};
}

}  // namespace

Forward forward_cuda(const at::Tensor& a, const at::Tensor& b, bool with_gradient) {
  const c10::cuda::CUDAGuard guard(a.device());
  const cudaStream_t stream = at::cuda::getCurrentCUDAStream();
  const ssim::cuda::Shape shape = shape_of(a);
  const at::Tensor block_sums = at::empty({ssim::cuda::forward_block_count(shape)}, a.options());
  Forward f;
  if (with_gradient) f.d_maps = at::empty({3, a.size(0), a.size(1), a.size(2)}, a.options());
  ssim::cuda::forward(shape, a.data_ptr<float>(), b.data_ptr<float>(), block_sums.data_ptr<float>(),
                      with_gradient ? f.d_maps.data_ptr<float>() : nullptr, stream);
  // Block sums reach ~1000 and there are ~10⁴ of them: add them in double.
  f.value = (block_sums.sum(at::kDouble) / double(a.numel())).to(at::kFloat);
  return f;
}

at::Tensor backward_cuda(const at::Tensor& a, const at::Tensor& b, const at::Tensor& d_maps,
                         const at::Tensor& grad_output) {
  const c10::cuda::CUDAGuard guard(a.device());
  const cudaStream_t stream = at::cuda::getCurrentCUDAStream();
  const at::Tensor g = grad_output.to(a.options()).contiguous();
  at::Tensor grad = at::empty(a.sizes(), a.options());
  ssim::cuda::backward(shape_of(a), a.data_ptr<float>(), b.data_ptr<float>(), d_maps.data_ptr<float>(),
                       g.data_ptr<float>(), float(1.0 / double(a.numel())), grad.data_ptr<float>(), stream);
  return grad;
}

}  // namespace tega::nn::fused_ssim_glue

#endif
