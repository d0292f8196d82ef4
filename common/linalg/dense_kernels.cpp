#include "common/linalg/dense_kernels.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <ctime>
#include <cstring>
#include <stdexcept>

#include "common/linalg/simd.hpp"

namespace sf::linalg {
namespace {

KernelIsa detect() {
#if SF_SIMD_X86
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return KernelIsa::kAvx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return KernelIsa::kAvx2;
#endif
  return KernelIsa::kGeneric;
}

KernelIsa from_environment(KernelIsa best) {
  const char* s = std::getenv("SF_KERNEL_ISA");
  if (s == nullptr) return best;
  KernelIsa want = best;
  if (std::strcmp(s, "generic") == 0) want = KernelIsa::kGeneric;
  if (std::strcmp(s, "avx2") == 0) want = KernelIsa::kAvx2;
  if (std::strcmp(s, "avx512") == 0) want = KernelIsa::kAvx512;
  return static_cast<int>(want) < static_cast<int>(best) ? want : best;
}

std::atomic<int>& current() {
  static std::atomic<int> isa{static_cast<int>(from_environment(best_kernel_isa()))};
  return isa;
}

// One register block: C(i0 .. i0 + MV W - 1, j0 .. j0 + NR - 1) = (or +=) the sum over the
// whole depth, with a = A(0, i0), b = B(0, j0), c = C(i0, j0). The MV NR accumulators stay
// in registers; each B entry is multiplied in as a scalar (a broadcast the compiler folds
// into the multiply-add's memory operand where the set has one).
template <int W, int MV, int NR, bool kAdd>
[[gnu::always_inline]] inline void atb_block(int depth, const double* a, int lda, const double* b, int ldb, double* c,
                                             int ldc) {
  using V = simd::Vec<W>;
  V acc[NR][MV];
  for (int j = 0; j < NR; ++j)
    for (int v = 0; v < MV; ++v) acc[j][v] = V{};
  for (int p = 0; p < depth; ++p, a += lda, b += ldb) {
    V av[MV];
    for (int v = 0; v < MV; ++v) av[v] = simd::at<W>(a + v * W);
    for (int j = 0; j < NR; ++j) {
      const double bj = b[j];
      for (int v = 0; v < MV; ++v) acc[j][v] += av[v] * bj;
    }
  }
  for (int j = 0; j < NR; ++j) {
    double* cp = c + static_cast<long>(j) * ldc;
    for (int v = 0; v < MV; ++v) {
      if (kAdd)
        simd::at<W>(cp + v * W) += acc[j][v];
      else
        simd::at<W>(cp + v * W) = acc[j][v];
    }
  }
}

// The lower triangle by blocks of NR columns; in each, the rows from the vector holding
// the diagonal down: first a block of the 1 .. MV - 1 vectors left over, then blocks of MV
// vectors (MR = MV W rows), so only the diagonal's own vector tile has entries above the
// diagonal. Needs n % W == 0 and n % NR == 0.
template <int W, int MV, int NR, bool kAdd>
[[gnu::always_inline]] inline void atb_lower_blocked(int n, int depth, const double* a, int lda, const double* b,
                                                     int ldb, double* c, int ldc) {
  for (int j0 = 0; j0 < n; j0 += NR) {
    int i0 = (j0 / W) * W;
    double* cj = c + static_cast<long>(j0) * ldc;
    const int lead = ((n - i0) / W) % MV;
    if (MV > 2 && lead == 2) {
      atb_block<W, (MV > 2 ? 2 : 1), NR, kAdd>(depth, a + i0, lda, b + j0, ldb, cj + i0, ldc);
      i0 += 2 * W;
    } else if (lead == 1) {
      atb_block<W, 1, NR, kAdd>(depth, a + i0, lda, b + j0, ldb, cj + i0, ldc);
      i0 += W;
    }
    for (; i0 < n; i0 += MV * W) atb_block<W, MV, NR, kAdd>(depth, a + i0, lda, b + j0, ldb, cj + i0, ldc);
  }
}

template <bool kAdd>
void atb_lower_scalar(int n, int depth, const double* a, int lda, const double* b, int ldb, double* c, int ldc) {
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      double s = 0.0;
      for (int p = 0; p < depth; ++p) s += a[static_cast<long>(p) * lda + i] * b[static_cast<long>(p) * ldb + j];
      if (kAdd)
        c[static_cast<long>(j) * ldc + i] += s;
      else
        c[static_cast<long>(j) * ldc + i] = s;
    }
}

template <int W, bool kAdd>
[[gnu::always_inline]] inline void atb_lower(int n, int depth, const double* a, int lda, const double* b, int ldb,
                                             double* c, int ldc) {
  // Block shapes: MV NR accumulators + MV loads within the register file (32 vector
  // registers with AVX-512, 16 otherwise; the broadcasts fold into the multiply-adds).
  constexpr int kMv = W == 8 ? 3 : 2, kNr = W == 8 ? 8 : 6;
  if (n % W == 0 && n % kNr == 0) return atb_lower_blocked<W, kMv, kNr, kAdd>(n, depth, a, lda, b, ldb, c, ldc);
  if (n % W == 0 && n % 4 == 0) return atb_lower_blocked<W, 2, 4, kAdd>(n, depth, a, lda, b, ldb, c, ldc);
  atb_lower_scalar<kAdd>(n, depth, a, lda, b, ldb, c, ldc);
}

// Packed operands (set_atb_lower_packed): A(p, i) at a[depth 8 (i / 8) + 8 p + i % 8], so
// each strip of 8 rows is one contiguous stream over the depth. A block of MV vectors x
// NR columns (NR within one strip of B) reads MV + 1 sequential streams.
template <int W, int MV, int NR>
[[gnu::always_inline]] inline void atb_block_packed(int depth, const double* a, int i0, const double* b, int j0,
                                                    double* c, int ldc) {
  using V = simd::Vec<W>;
  const long strip = 8L * depth;
  const double* ap[MV];
  for (int v = 0; v < MV; ++v) ap[v] = a + strip * ((i0 + v * W) / 8) + (i0 + v * W) % 8;
  const double* bp = b + strip * (j0 / 8) + j0 % 8;
  V acc[NR][MV];
  for (int j = 0; j < NR; ++j)
    for (int v = 0; v < MV; ++v) acc[j][v] = V{};
  for (long p = 0; p < 8L * depth; p += 8) {
    V av[MV];
    for (int v = 0; v < MV; ++v) av[v] = simd::at<W>(ap[v] + p);
    for (int j = 0; j < NR; ++j) {
      const double bj = bp[p + j];
      for (int v = 0; v < MV; ++v) acc[j][v] += av[v] * bj;
    }
  }
  for (int j = 0; j < NR; ++j) {
    double* cp = c + static_cast<long>(j0 + j) * ldc + i0;
    for (int v = 0; v < MV; ++v) simd::at<W>(cp + v * W) = acc[j][v];
  }
}

template <int W>
[[gnu::always_inline]] inline void atb_lower_packed(int n, int depth, const double* a, const double* b, double* c,
                                                    int ldc) {
  // MV W rows a block, NR columns (NR divides 8: the columns stay in one strip of B).
  constexpr int kMv = W == 8 ? 3 : 2, kNr = W == 8 ? 8 : 4;
  for (int j0 = 0; j0 < n; j0 += kNr) {
    int i0 = (j0 / W) * W;
    const int lead = ((n - i0) / W) % kMv;
    if (kMv > 2 && lead == 2) {
      atb_block_packed<W, (kMv > 2 ? 2 : 1), kNr>(depth, a, i0, b, j0, c, ldc);
      i0 += 2 * W;
    } else if (lead == 1) {
      atb_block_packed<W, 1, kNr>(depth, a, i0, b, j0, c, ldc);
      i0 += W;
    }
    for (; i0 < n; i0 += kMv * W) atb_block_packed<W, kMv, kNr>(depth, a, i0, b, j0, c, ldc);
  }
}

SF_SIMD_AVX512 void atb_lower_packed_avx512(int n, int depth, const double* a, const double* b, double* c, int ldc) {
  atb_lower_packed<8>(n, depth, a, b, c, ldc);
}
SF_SIMD_AVX2 void atb_lower_packed_avx2(int n, int depth, const double* a, const double* b, double* c, int ldc) {
  atb_lower_packed<4>(n, depth, a, b, c, ldc);
}
void atb_lower_packed_generic(int n, int depth, const double* a, const double* b, double* c, int ldc) {
  atb_lower_packed<2>(n, depth, a, b, c, ldc);
}

#define SF_ATB_VARIANTS(attr, suffix, W)                                                                     \
  attr void atb_lower_##suffix(bool add, int n, int depth, const double* a, int lda, const double* b, int ldb, \
                               double* c, int ldc) {                                                           \
    if (add)                                                                                                   \
      atb_lower<W, true>(n, depth, a, lda, b, ldb, c, ldc);                                                    \
    else                                                                                                       \
      atb_lower<W, false>(n, depth, a, lda, b, ldb, c, ldc);                                                   \
  }
SF_ATB_VARIANTS(SF_SIMD_AVX512, avx512, 8)
SF_ATB_VARIANTS(SF_SIMD_AVX2, avx2, 4)
SF_ATB_VARIANTS(, generic, 2)
#undef SF_ATB_VARIANTS

void atb_lower_dispatch(bool add, int n, int depth, const double* a, int lda, const double* b, int ldb, double* c,
                        int ldc) {
  switch (kernel_isa()) {
    case KernelIsa::kAvx512:
      return atb_lower_avx512(add, n, depth, a, lda, b, ldb, c, ldc);
    case KernelIsa::kAvx2:
      return atb_lower_avx2(add, n, depth, a, lda, b, ldb, c, ldc);
    case KernelIsa::kGeneric:
      break;
  }
  atb_lower_generic(add, n, depth, a, lda, b, ldb, c, ldc);
}

// n rounds of kChains independent multiply-add chains of W lanes: kChains covers the
// FMA latency times the units (4 x 2 on recent x86) with registers to spare.
template <int W>
[[gnu::always_inline]] inline double fma_chains(long n) {
  constexpr int kChains = 12;
  simd::Vec<W> acc[kChains];
  for (int i = 0; i < kChains; ++i) acc[i] = simd::Vec<W>{} + (1.0 + 1e-3 * i);
  const simd::Vec<W> m = simd::Vec<W>{} + 0.999999999, c = simd::Vec<W>{} + 1e-9;
  for (long k = 0; k < n; ++k)
#pragma GCC unroll 12  // the chains in registers, not in memory, at any -O level
    for (int i = 0; i < kChains; ++i) acc[i] = acc[i] * m + c;
  double s = 0.0;
  for (int i = 0; i < kChains; ++i) s += simd::sum<W>(acc[i]);
  return s;
}
SF_SIMD_AVX512 double fma_chains_avx512(long n) { return fma_chains<8>(n); }
SF_SIMD_AVX2 double fma_chains_avx2(long n) { return fma_chains<4>(n); }
double fma_chains_generic(long n) { return fma_chains<2>(n); }

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

std::string to_string(KernelIsa isa) {
  switch (isa) {
    case KernelIsa::kAvx512:
      return "avx512";
    case KernelIsa::kAvx2:
      return "avx2";
    case KernelIsa::kGeneric:
      break;
  }
  return "generic";
}

KernelIsa best_kernel_isa() {
  static const KernelIsa best = detect();
  return best;
}

KernelIsa kernel_isa() { return static_cast<KernelIsa>(current().load(std::memory_order_relaxed)); }

KernelIsa set_kernel_isa(KernelIsa isa) {
  const KernelIsa best = best_kernel_isa();
  const KernelIsa use = static_cast<int>(isa) < static_cast<int>(best) ? isa : best;
  current().store(static_cast<int>(use), std::memory_order_relaxed);
  return use;
}

int vector_width(KernelIsa isa) {
  switch (isa) {
    case KernelIsa::kAvx512:
      return 8;
    case KernelIsa::kAvx2:
      return 4;
    case KernelIsa::kGeneric:
      break;
  }
  return 2;
}

void add_atb_lower(int n, int depth, const double* a, int lda, const double* b, int ldb, double* c, int ldc) {
  atb_lower_dispatch(true, n, depth, a, lda, b, ldb, c, ldc);
}

void set_atb_lower(int n, int depth, const double* a, int lda, const double* b, int ldb, double* c, int ldc) {
  atb_lower_dispatch(false, n, depth, a, lda, b, ldb, c, ldc);
}

void set_atb_lower_packed(int n, int depth, const double* a, const double* b, double* c, int ldc) {
  if (n % 8 != 0) throw std::invalid_argument("set_atb_lower_packed: n must be a multiple of 8");
  switch (kernel_isa()) {
    case KernelIsa::kAvx512:
      return atb_lower_packed_avx512(n, depth, a, b, c, ldc);
    case KernelIsa::kAvx2:
      return atb_lower_packed_avx2(n, depth, a, b, c, ldc);
    case KernelIsa::kGeneric:
      break;
  }
  atb_lower_packed_generic(n, depth, a, b, c, ldc);
}

double fma_peak_gflops(double seconds) {
  const KernelIsa isa = kernel_isa();
  const auto run = [isa](long n) {
    switch (isa) {
      case KernelIsa::kAvx512:
        return fma_chains_avx512(n);
      case KernelIsa::kAvx2:
        return fma_chains_avx2(n);
      case KernelIsa::kGeneric:
        break;
    }
    return fma_chains_generic(n);
  };
  // 2 flops a lane a multiply-add, 12 chains (fma_chains); the best of the timed rounds.
  const double flops_per_round = 2.0 * 12 * vector_width(isa);
  long n = 1 << 16;
  volatile double sink = 0.0;
  double best = 0.0, spent = 0.0;
  while (spent < seconds || best == 0.0) {
    const double t0 = thread_seconds();
    sink = sink + run(n);
    const double dt = thread_seconds() - t0;
    spent += dt;
    if (dt < 0.02) {
      n *= 4;  // too short to time
      continue;
    }
    best = std::max(best, flops_per_round * static_cast<double>(n) / dt / 1e9);
  }
  return best;
}

}  // namespace sf::linalg
