// CUDA kernel of the fused Adam update: a grid-stride pass over the elements.

#include "adam_update_kernels.h"

#include "tega/core/cuda_check.h"

namespace tega::trainer::adam_update::cuda {
namespace {

template <typename T>
__global__ void step_kernel(int64_t count, int64_t columns, T* param, const T* grad, T* first_moment,
                            T* second_moment, const T* column_scale, Constants<T> constants) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < count; i += int64_t(gridDim.x) * blockDim.x)
    step_element(param[i], grad[i], first_moment[i], second_moment[i],
                 column_scale ? column_scale[i % columns] : T(1), constants);
}

}  // namespace

template <typename T>
void step(int64_t count, int64_t columns, T* param, const T* grad, T* first_moment, T* second_moment,
          const T* column_scale, const Constants<T>& constants, cudaStream_t stream) {
  if (count == 0) return;
  constexpr int kThreads = 256;
  const int64_t blocks = (count + kThreads - 1) / kThreads;
  step_kernel<T><<<unsigned(blocks < 65536 ? blocks : 65536), kThreads, 0, stream>>>(
      count, columns, param, grad, first_moment, second_moment, column_scale, constants);
  check_launch("adam", "step_kernel");
}

template void step<float>(int64_t, int64_t, float*, const float*, float*, float*, const float*,
                          const Constants<float>&, cudaStream_t);
template void step<double>(int64_t, int64_t, double*, const double*, double*, double*, const double*,
                           const Constants<double>&, cudaStream_t);

}  // namespace tega::trainer::adam_update::cuda
