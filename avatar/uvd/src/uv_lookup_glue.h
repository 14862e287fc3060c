#pragma once
// The CUDA side of UvTriangleLookup::lookup (uv_lookup.cpp runs the CPU loop
// itself): uv [N,2] contiguous on the grid's device.

#include <ATen/core/Tensor.h>

#include "uv_lookup_math.h"

namespace tega::uvd::uv_lookup {

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
template <typename T>
void lookup_cuda(const Grid<T>& grid, const at::Tensor& uv, const Answers<T>& out);
#endif

}  // namespace tega::uvd::uv_lookup
