// One thread per point: it gathers its triangle's tables and its three
// corners' positions and normals (scattered reads that the caches serve, the
// mesh being small next to the points), and reads and writes its own rows.

#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"
#include "fused_uvd_map_kernels.h"

namespace tega::uvd::fused_uvd_map::cuda {
namespace {

constexpr int kThreads = 256;

template <typename T>
__global__ void forward_kernel(int64_t n, Surface<T> surface, const int64_t* __restrict__ triangle,
                               const T* __restrict__ uv, const T* __restrict__ uvd, T* __restrict__ xyz,
                               T* __restrict__ jacobian) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    forward_element(surface, triangle[i], uv + 2 * i, uvd[3 * i + 2], xyz + 3 * i, jacobian + 9 * i);
}

template <typename T>
__global__ void backward_kernel(int64_t n, Surface<T> surface, const int64_t* __restrict__ triangle,
                                const T* __restrict__ uv, const T* __restrict__ uvd, const T* __restrict__ grad_xyz,
                                const T* __restrict__ grad_jacobian, T* __restrict__ grad_uvd) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += int64_t(gridDim.x) * blockDim.x)
    backward_element(surface, triangle[i], uv + 2 * i, uvd[3 * i + 2], grad_xyz ? grad_xyz + 3 * i : nullptr,
                     grad_jacobian ? grad_jacobian + 9 * i : nullptr, grad_uvd + 3 * i);
}

}  // namespace

template <typename T>
void forward(int64_t n, const Surface<T>& surface, const int64_t* triangle, const T* uv, const T* uvd, T* xyz,
             T* jacobian, cudaStream_t stream) {
  if (n == 0) return;
  forward_kernel<<<grid_stride_blocks(n, kThreads), kThreads, 0, stream>>>(n, surface, triangle, uv, uvd, xyz,
                                                                           jacobian);
  check_launch("uvd_to_world", "forward_kernel");
}

template <typename T>
void backward(int64_t n, const Surface<T>& surface, const int64_t* triangle, const T* uv, const T* uvd,
              const T* grad_xyz, const T* grad_jacobian, T* grad_uvd, cudaStream_t stream) {
  if (n == 0) return;
  backward_kernel<<<grid_stride_blocks(n, kThreads), kThreads, 0, stream>>>(n, surface, triangle, uv, uvd, grad_xyz,
                                                                            grad_jacobian, grad_uvd);
  check_launch("uvd_to_world", "backward_kernel");
}

template void forward<float>(int64_t, const Surface<float>&, const int64_t*, const float*, const float*, float*,
                             float*, cudaStream_t);
template void forward<double>(int64_t, const Surface<double>&, const int64_t*, const double*, const double*, double*,
                              double*, cudaStream_t);
template void backward<float>(int64_t, const Surface<float>&, const int64_t*, const float*, const float*,
                              const float*, const float*, float*, cudaStream_t);
template void backward<double>(int64_t, const Surface<double>&, const int64_t*, const double*, const double*,
                               const double*, const double*, double*, cudaStream_t);

}  // namespace tega::uvd::fused_uvd_map::cuda
