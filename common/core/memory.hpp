#pragma once
// Process-wide memory settings for the programs that run Newton solves, and gsa
// (its noise estimate frees and allocates again probe matrices of tens of MB).

namespace sf {

// Keeps memory the process frees for its own reuse instead of returning it to the
// system (glibc: malloc never maps large blocks separately, the heap is never trimmed).
//
// Why: a Newton iteration frees and allocates again buffers of tens of MB (CHOLMOD's
// permuted copy of the matrix and its workspace, the right-hand sides). glibc serves
// blocks above its mmap threshold (at most 32 MiB) with a fresh mapping each time, so
// every factorisation paid page faults and the kernel's zeroing of those pages: on a
// 20x20 ply they took more time than the factorisation itself (0.47 s against 0.12-0.18 s
// without, simform_bench). The price is that the peak resident memory is not given back
// until the process ends, which a solver process does soon after its peak anyway.
// Call once at the start of main(), before large allocations. No effect on other C
// libraries.
void keep_freed_memory();

}  // namespace sf
