#pragma once
// Process-wide memory settings for the programs that run Newton solves, and gsa
// (its noise estimate frees and allocates again probe matrices of tens of MB).

namespace sf {

// Keeps memory the process frees for its own reuse instead of returning it to the
// system (glibc: malloc never maps large blocks separately, the heap is never trimmed).
//
// Why: a Newton iteration frees and allocates again buffers of tens to hundreds of MB
// (CHOLMOD's permuted copy of the matrix and its workspace, UMFPACK's numeric object, the
// right-hand sides). glibc serves blocks above its mmap threshold (at most 32 MiB) with a
// fresh mapping each time, so every factorisation paid page faults and the kernel's
// zeroing of those pages: on a 20x20 ply they took more time than the factorisation
// itself (0.47 s against 0.12-0.18 s without, simform_bench); on the quick dome 175 k page
// faults and 60 % of the processor time, against 17 k with the memory kept. The price is
// that the peak resident memory is not given back until the process ends, which a solver
// process does soon after its peak anyway.
//
// Call once at the start of main(), before large allocations (simform, gsa and the
// benches do; libraries never do: a process-wide malloc setting is the program's choice).
// Left alone when the user tunes malloc (GLIBC_TUNABLES naming glibc.malloc, or
// MALLOC_MMAP_MAX_ / MALLOC_MMAP_THRESHOLD_ / MALLOC_TRIM_THRESHOLD_ set). Returns true
// when the settings are in force (the same answer on every call). No effect on other C
// libraries (returns false).
bool keep_freed_memory();

}  // namespace sf
