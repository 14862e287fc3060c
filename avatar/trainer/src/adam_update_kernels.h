#pragma once
// Launcher of the Adam update kernel (adam_update.cu): raw pointers, no torch
// types, so nvcc compiles it in C++17.

#include <cuda_runtime_api.h>

#include <cstdint>

#include "adam_update_math.h"

namespace tega::trainer::adam_update::cuda {

template <typename T>
void step(int64_t count, int64_t columns, T* param, const T* grad, T* first_moment, T* second_moment,
          const T* column_scale, const Constants<T>& constants, cudaStream_t stream);

}  // namespace tega::trainer::adam_update::cuda
