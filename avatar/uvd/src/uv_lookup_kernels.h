#pragma once
// The CUDA kernel of UvTriangleLookup::lookup (float and double): raw device
// pointers; the torch glue (uv_lookup_cuda.cpp) allocates the answers and
// picks the stream. uv [N,2] contiguous.

#include <cuda_runtime_api.h>

#include <cstdint>

#include "uv_lookup_math.h"

namespace tega::uvd::uv_lookup::cuda {

template <typename T>
void lookup(int64_t n, const Grid<T>& grid, const T* uv, const Answers<T>& out, cudaStream_t stream);

}  // namespace tega::uvd::uv_lookup::cuda
