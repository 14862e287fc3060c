#include "heap.h"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace tega::cli {

void keep_freed_memory_for_reuse() {
#ifdef __GLIBC__
  constexpr int kOneGiB = 1 << 30;
  mallopt(M_MMAP_THRESHOLD, kOneGiB);  // blocks up to this come from the heap, not mmap
  mallopt(M_TRIM_THRESHOLD, kOneGiB);  // and the heap's free top stays mapped
#endif
}

}  // namespace tega::cli
