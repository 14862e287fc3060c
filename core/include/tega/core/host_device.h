#pragma once
// Qualifiers of the math shared by the CPU paths and the CUDA kernels of
// avatar/ and mvs/ (plain C++17 without torch types): nvcc compiles it as
// __host__ __device__, g++ as ordinary inline functions.

#if defined(__CUDACC__)
#define TEGA_HD __host__ __device__ __forceinline__
// Fully unrolled loops index register arrays with constants, keeping them
// out of local memory.
#define TEGA_UNROLL _Pragma("unroll")
#else
#define TEGA_HD inline
#define TEGA_UNROLL
#endif
