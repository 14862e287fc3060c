#pragma once

namespace tega::cli {

// Keeps memory that large CPU tensors free on the heap for the next ones. glibc hands each block
// over its mmap threshold straight back to the kernel, so every libtorch op's output on the CPU
// is fresh pages, faulted in one by one: at 640 x 480, eval spent half its time in page faults
// (41 s, 20 with the blocks kept). Each command is one short-lived process, so the kept memory
// is never more than its peak. A no-op where the C library is not glibc.
void keep_freed_memory_for_reuse();

}  // namespace tega::cli
