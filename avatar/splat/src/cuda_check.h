#pragma once
// Error checks of the CUDA pipeline: a failed call or launch throws with
// what failed.

#include <cuda_runtime_api.h>

#include <stdexcept>
#include <string>

namespace tega::splat::cuda {

inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("tega splat: ") + what + ": " + cudaGetErrorString(status));
}

}  // namespace tega::splat::cuda

#define TEGA_CUDA_CHECK(expr) ::tega::splat::cuda::check((expr), #expr)
#define TEGA_CHECK_LAUNCH(kernel) ::tega::splat::cuda::check(cudaGetLastError(), "launching " #kernel)
