#pragma once
// Grid sizes of the grid-stride CUDA kernels of avatar/: one thread per
// element up to enough blocks to fill an H100 (132 multiprocessors) many times
// over; the kernels' loops stride over the rest.

#include <algorithm>
#include <cstdint>

namespace tega {

inline unsigned grid_stride_blocks(int64_t count, int threads) {
  constexpr int64_t kMaxBlocks = 132 * 64;
  return unsigned(std::min<int64_t>((count + threads - 1) / threads, kMaxBlocks));
}

}  // namespace tega
