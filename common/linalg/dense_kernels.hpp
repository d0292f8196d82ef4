#pragma once
// Small dense kernels for element matrices, compiled for several instruction sets and
// chosen at run time (common/linalg/simd.hpp says how).
//
// Instruction set
//   kernel_isa() is the widest set the processor supports (cpuid): AVX-512 (8 doubles
//   per register, FMA), AVX2 + FMA (4), or generic SSE2 (2, every x86-64). The
//   environment variable SF_KERNEL_ISA=generic|avx2|avx512 lowers it (never above what
//   the processor has), as does set_kernel_isa(); results of different sets differ by
//   rounding only (FMA), results of one set are the same on every run and thread count.
//
// Products
//   add_atb_lower: C += A^T B on the lower triangle (i >= j) of an n x n column-major C,
//   with A and B given as depth rows of n contiguous entries (row p of A starts at
//   a + p * lda). For an element tangent K = sum_q B_q^T (D_q B_q) this is the whole sum
//   over Gauss points in one call: the rows of A are the B_q, those of B the D_q B_q.
//   Entries above the diagonal may receive partial sums (ignore them).
//   set_atb_lower: the same with C = A^T B on the lower triangle (C need not be zeroed;
//   entries above the diagonal may be overwritten).
//
// Flops: n (n + 1) depth for the lower triangle (what add_atb_lower_flops() returns).

#include <string>

namespace sf::linalg {

enum class KernelIsa { kGeneric = 0, kAvx2 = 1, kAvx512 = 2 };

// "generic", "avx2", "avx512".
std::string to_string(KernelIsa isa);
// Widest set the processor supports.
KernelIsa best_kernel_isa();
// Set in use (best_kernel_isa() lowered by SF_KERNEL_ISA or set_kernel_isa()).
KernelIsa kernel_isa();
// Uses `isa` from now on, capped at best_kernel_isa(); returns the set in use.
KernelIsa set_kernel_isa(KernelIsa isa);
// Doubles per vector register of a set (2, 4, 8).
int vector_width(KernelIsa isa);

// C(i, j) += sum_p A(p, i) B(p, j) for n > i >= j >= 0; A(p, i) = a[p * lda + i],
// B(p, j) = b[p * ldb + j], C(i, j) = c[j * ldc + i].
void add_atb_lower(int n, int depth, const double* a, int lda, const double* b, int ldb, double* c, int ldc);
// C(i, j) = sum_p A(p, i) B(p, j) for n > i >= j >= 0 (same layout as add_atb_lower).
void set_atb_lower(int n, int depth, const double* a, int lda, const double* b, int ldb, double* c, int ldc);
// The same from packed operands: A(p, i) = a[depth 8 (i / 8) + 8 p + i % 8] (each strip
// of 8 columns of A stored depth-major, so a block reads contiguous memory), B likewise;
// n a multiple of 8 (std::invalid_argument otherwise). packed_index() gives the position.
void set_atb_lower_packed(int n, int depth, const double* a, const double* b, double* c, int ldc);
inline long packed_index(int depth, int p, int i) { return 8L * depth * (i / 8) + 8L * p + i % 8; }
inline double add_atb_lower_flops(int n, int depth) { return double(n) * (n + 1) * depth; }

// The calling thread's attainable double-precision rate with the vector set in use,
// GFLOP/s: independent chains of fused multiply-adds (no memory traffic) for about
// `seconds`, timed on the thread's processor clock. What one core can do at most with
// kernel_isa() (both FMA units busy where the processor has two); benchmarks run it on
// each of their threads at once and compare their kernels' rates with the sum.
double fma_peak_gflops(double seconds = 0.2);

}  // namespace sf::linalg
