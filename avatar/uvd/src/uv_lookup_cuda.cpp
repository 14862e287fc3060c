// Torch glue of the uv lookup's CUDA kernel: the kernel on the current stream.

#include "uv_lookup_glue.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>

#include "uv_lookup_kernels.h"

namespace tega::uvd::uv_lookup {

template <typename T>
void lookup_cuda(const Grid<T>& grid, const at::Tensor& uv, const Answers<T>& out) {
  const c10::cuda::CUDAGuard guard(uv.device());
  cuda::lookup(uv.size(0), grid, uv.data_ptr<T>(), out, at::cuda::getCurrentCUDAStream());
}

template void lookup_cuda<float>(const Grid<float>&, const at::Tensor&, const Answers<float>&);
template void lookup_cuda<double>(const Grid<double>&, const at::Tensor&, const Answers<double>&);

}  // namespace tega::uvd::uv_lookup

#endif
