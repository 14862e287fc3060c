#pragma once
// Error checks shared by the CUDA code of avatar/ and mvs/: a failed call or
// kernel launch throws, naming the op and what failed.

#include <cuda_runtime_api.h>

#include <stdexcept>
#include <string>

namespace tega {

inline void check_cuda(cudaError_t status, const char* op, const char* what) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("tega ") + op + ": " + what + ": " + cudaGetErrorString(status));
}

// After a kernel launch: a bad configuration shows up here, not at the next sync.
inline void check_launch(const char* op, const char* kernel) {
  check_cuda(cudaGetLastError(), op, (std::string("launching ") + kernel).c_str());
}

}  // namespace tega
