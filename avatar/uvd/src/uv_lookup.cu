// One thread per query: its texel's offsets, then its candidates' corner and
// inverse tables (a few scattered reads that the caches serve, the layout
// being small next to the queries).

#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"
#include "uv_lookup_kernels.h"

namespace tega::uvd::uv_lookup::cuda {
namespace {

constexpr int kThreads = 256;

template <typename T>
__global__ void lookup_kernel(int64_t n, Grid<T> grid, const T* __restrict__ uv, Answers<T> out) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    lookup_point(grid, uv, i, out);
}

}  // namespace

template <typename T>
void lookup(int64_t n, const Grid<T>& grid, const T* uv, const Answers<T>& out, cudaStream_t stream) {
  if (n == 0) return;
  lookup_kernel<<<grid_stride_blocks(n, kThreads), kThreads, 0, stream>>>(n, grid, uv, out);
  check_launch("uv lookup", "lookup_kernel");
}

template void lookup<float>(int64_t, const Grid<float>&, const float*, const Answers<float>&, cudaStream_t);
template void lookup<double>(int64_t, const Grid<double>&, const double*, const Answers<double>&, cudaStream_t);

}  // namespace tega::uvd::uv_lookup::cuda
