#pragma once
// Fixed-width double vectors for kernels that are compiled once per instruction set and
// chosen at run time (common/linalg/dense_kernels.hpp: kernel_isa()).
//
// How a kernel uses them: write the loop body once as a template over the width W
// (doubles per vector) with these helpers, mark it always_inline, and instantiate it
// inside one wrapper per instruction set:
//   SF_SIMD_AVX512 void f_avx512(...) { f_impl<8>(...); }   // 512-bit registers, FMA
//   SF_SIMD_AVX2   void f_avx2(...)   { f_impl<4>(...); }   // 256-bit registers, FMA
//                  void f_generic(...) { f_impl<2>(...); }  // SSE2, every x86-64
// then switch on kernel_isa(). The compiler lowers the vector operations to the
// wrapper's instruction set; no -m flag is needed on the file and the default build
// runs on any x86-64 processor. On other processors every wrapper is the generic one.
// Files holding such kernels are compiled with -ffp-contract=fast (common/CMakeLists.txt
// and forming/CMakeLists.txt) so that a * b + c becomes one fused multiply-add.
//
// GCC and Clang vector extensions; no intrinsics, no inline assembly.

namespace sf::linalg::simd {

template <int W>
struct VecOf {
  typedef double type __attribute__((vector_size(8 * W)));
  // The same at any address of a double (unaligned loads and stores).
  typedef double unaligned __attribute__((vector_size(8 * W), aligned(8), may_alias));
};
// A vector of W doubles; `Vec<W>{} + s` broadcasts the scalar s.
template <int W>
using Vec = typename VecOf<W>::type;

// The W doubles at p as one vector, to read (`Vec<W> v = at<W>(p)`) or to update
// (`at<W>(p) += v`). References, not values: no vector crosses a function boundary
// whose instruction set differs from the wrapper's (GCC's ABI note on wide vectors).
template <int W>
[[gnu::always_inline]] inline const typename VecOf<W>::unaligned& at(const double* p) {
  return *reinterpret_cast<const typename VecOf<W>::unaligned*>(p);
}
template <int W>
[[gnu::always_inline]] inline typename VecOf<W>::unaligned& at(double* p) {
  return *reinterpret_cast<typename VecOf<W>::unaligned*>(p);
}
template <int W, class V>
[[gnu::always_inline]] inline double sum(const V& v) {
  double s = 0.0;
  for (int i = 0; i < W; ++i) s += v[i];
  return s;
}

}  // namespace sf::linalg::simd

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SF_SIMD_X86 1
#define SF_SIMD_AVX512 __attribute__((target("avx512f,avx2,fma")))
#define SF_SIMD_AVX2 __attribute__((target("avx2,fma")))
#else
#define SF_SIMD_X86 0
#define SF_SIMD_AVX512
#define SF_SIMD_AVX2
#endif
