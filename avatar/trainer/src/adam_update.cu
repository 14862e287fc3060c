// CUDA kernels of the fused Adam update: grid-stride passes over the
// elements. Adam reads four tensors and writes three, so it runs at memory
// speed; in float, where the tensors allow, four elements a thread move as
// 16-byte words.

#include <cstdint>
#include <type_traits>

#include "adam_update_kernels.h"
#include "tega/core/cuda_check.h"
#include "tega/core/cuda_grid.h"

namespace tega::trainer::adam_update::cuda {
namespace {

constexpr int kThreads = 256;

template <typename T>
__global__ void step_kernel(int64_t count, int64_t columns, T* param, const T* grad, T* first_moment,
                            T* second_moment, const T* column_scale, Constants<T> constants) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x)
    step_element(param[i], grad[i], first_moment[i], second_moment[i],
                 column_scale ? column_scale[i % columns] : T(1), constants);
}

__global__ void step_kernel_by_four(int64_t quads, int64_t columns, float4* param, const float4* grad,
                                    float4* first_moment, float4* second_moment, const float* column_scale,
                                    Constants<float> constants) {
  for (int64_t q = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; q < quads; q += int64_t(gridDim.x) * blockDim.x) {
    float4 p = param[q], m = first_moment[q], v = second_moment[q];
    const float4 g = grad[q];
    float scale[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    if (column_scale) {
      int64_t column = (4 * q) % columns;
      for (int k = 0; k < 4; ++k, column = column + 1 == columns ? 0 : column + 1) scale[k] = column_scale[column];
    }
    step_element(p.x, g.x, m.x, v.x, scale[0], constants);
    step_element(p.y, g.y, m.y, v.y, scale[1], constants);
    step_element(p.z, g.z, m.z, v.z, scale[2], constants);
    step_element(p.w, g.w, m.w, v.w, scale[3], constants);
    param[q] = p;
    first_moment[q] = m;
    second_moment[q] = v;
  }
}

}  // namespace

template <typename T>
void step(int64_t count, int64_t columns, T* param, const T* grad, T* first_moment, T* second_moment,
          const T* column_scale, const Constants<T>& constants, cudaStream_t stream) {
  if (count == 0) return;
  if constexpr (std::is_same_v<T, float>) {
    if (count % 4 == 0 && aligned_to_16_bytes(param) && aligned_to_16_bytes(grad) &&
        aligned_to_16_bytes(first_moment) && aligned_to_16_bytes(second_moment)) {
      step_kernel_by_four<<<grid_stride_blocks(count / 4, kThreads), kThreads, 0, stream>>>(
          count / 4, columns, reinterpret_cast<float4*>(param), reinterpret_cast<const float4*>(grad),
          reinterpret_cast<float4*>(first_moment), reinterpret_cast<float4*>(second_moment), column_scale,
          constants);
      check_launch("adam", "step_kernel_by_four");
      return;
    }
  }
  step_kernel<T><<<grid_stride_blocks(count, kThreads), kThreads, 0, stream>>>(
      count, columns, param, grad, first_moment, second_moment, column_scale, constants);
  check_launch("adam", "step_kernel");
}

template void step<float>(int64_t, int64_t, float*, const float*, float*, float*, const float*,
                          const Constants<float>&, cudaStream_t);
template void step<double>(int64_t, int64_t, double*, const double*, double*, double*, const double*,
                           const Constants<double>&, cudaStream_t);

}  // namespace tega::trainer::adam_update::cuda
