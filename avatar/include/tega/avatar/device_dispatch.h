#pragma once
// Whether an op with its own CUDA kernels runs them: for tensors on a GPU,
// in a build that has both the kernels (nvcc) and a CUDA libtorch. A tensor
// on a GPU in a build without them is an error naming the op.

#include <ATen/core/Tensor.h>
#include <c10/util/Exception.h>

namespace tega {

inline bool use_cuda_kernels(const at::Tensor& t, [[maybe_unused]] const char* op) {
  if (!t.is_cuda()) return false;
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
  return true;
#else
  TORCH_CHECK(false, op, ": tensors are on a GPU but this build has no CUDA kernels");
#endif
}

}  // namespace tega
