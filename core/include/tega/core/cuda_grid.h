#pragma once
// Launch choices of the CUDA kernels of avatar/. Grid sizes of the
// grid-stride kernels: one thread per element up to enough blocks to fill an
// H100 (132 multiprocessors) many times over; the kernels' loops stride over
// the rest. And whether a pointer suits 16-byte vector loads.

#include <algorithm>
#include <cstdint>

namespace tega {

inline unsigned grid_stride_blocks(int64_t count, int threads) {
  constexpr int64_t kMaxBlocks = 132 * 64;
  return unsigned(std::min<int64_t>((count + threads - 1) / threads, kMaxBlocks));
}

inline bool aligned_to_16_bytes(const void* pointer) { return reinterpret_cast<uintptr_t>(pointer) % 16 == 0; }

}  // namespace tega
