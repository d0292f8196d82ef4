#pragma once
// One-dimensional and tensor-product element bases on the unit cell [0,1]^d.
//
// 1-D cubic Hermite on t in [0,1] (index order used everywhere):
//   H0 = 1 - 3t^2 + 2t^3   value at t=0
//   H1 = t (t-1)^2         derivative at t=0
//   H2 = t^2 (3 - 2t)      value at t=1
//   H3 = t^2 (t-1)         derivative at t=1
// 1-D linear Lagrange: L0 = 1 - t, L1 = t.
//
// Bicubic Hermite (surfaces), 16 functions. Local nodes, xi1 fastest:
//
//      xi2
//       ^
//   n2 (0,1) ---- n3 (1,1)
//       |            |
//   n0 (0,0) ---- n1 (1,0)  -> xi1
//
// Each node has 4 parameters, in the order  d = 0 value, 1 d/dxi1, 2 d/dxi2,
// 3 d2/dxi1dxi2;  function index k = 4*n + d.  With n = a + 2b (a, b in {0,1})
// and d = k1 + 2*k2, function k is H_{2a+k1}(xi1) * H_{2b+k2}(xi2).
//
// Bicubic Hermite x linear (ply bricks), 32 functions: 8 nodes n = a + 2b + 4c,
// c = 0 bottom face (xi3 = 0), c = 1 top face; 4 parameters per node as above;
// k = 4*n + d; function = H(xi1) H(xi2) L_c(xi3).
//
// Cubic Hermite x linear (plane-strain plies), 8 functions: 4 nodes n = a + 2c,
// 2 parameters per node (value, d/dxi1); k = 2*n + d; function = H_{2a+d}(xi1) L_c(xi2).
//
// All functions here work in xi; scale factors (arc length) are applied by the
// element parameter map (common/mesh), not by the basis.

#include <Eigen/Core>
#include <array>

namespace sf::basis {

// The four cubic Hermite functions and their derivatives up to order N (0 <= N <= 3)
// at t, in one inline call: table[k][i] = d^k H_i / dt^k. This is the fast path of the
// hot loops (nearest-point projection evaluates values to second derivatives millions of
// times; the fit's penalties need third derivatives) and the one place the polynomials
// are written down: cubic_hermite() and every tensor basis below take them from here.
template <int N>
using CubicHermiteTable = std::array<std::array<double, 4>, N + 1>;

template <int N>
inline CubicHermiteTable<N> cubic_hermite_table(double t) {
  static_assert(N >= 0 && N <= 3, "cubic Hermite derivatives of order 0 to 3");
  const double t2 = t * t;
  CubicHermiteTable<N> h;
  h[0] = {1.0 - 3.0 * t2 + 2.0 * t2 * t, t * (t - 1.0) * (t - 1.0), t2 * (3.0 - 2.0 * t), t2 * (t - 1.0)};
  if constexpr (N >= 1) h[1] = {-6.0 * t + 6.0 * t2, 1.0 - 4.0 * t + 3.0 * t2, 6.0 * t - 6.0 * t2, -2.0 * t + 3.0 * t2};
  if constexpr (N >= 2) h[2] = {-6.0 + 12.0 * t, -4.0 + 6.0 * t, 6.0 - 12.0 * t, -2.0 + 6.0 * t};
  if constexpr (N >= 3) h[3] = {12.0, 6.0, -12.0, 6.0};
  return h;
}

// Derivative of order `derivative_order` (0 = values) of the four cubic Hermite functions;
// zeros above order 3.
std::array<double, 4> cubic_hermite(double t, int derivative_order);
// Values or first derivative of the two linear Lagrange functions (second derivative is 0).
std::array<double, 2> linear_lagrange(double t, int derivative_order);

// What an evaluation should compute (deal.II-style update flags); combine with |.
enum Update : unsigned {
  kValues = 1u,
  kFirst = 2u,   // first xi-derivatives
  kSecond = 4u,  // second xi-derivatives
};

// Result of evaluating a tensor basis with NF functions in DIM dimensions.
// second derivative columns: 2-D (11, 12, 22); 3-D (11, 12, 13, 22, 23, 33).
template <int NF, int DIM>
struct BasisValues {
  static constexpr int kNumFunctions = NF;
  static constexpr int kDim = DIM;
  static constexpr int kNumSecond = DIM * (DIM + 1) / 2;
  unsigned updated = 0;                          // which flags were computed
  Eigen::Matrix<double, NF, 1> value;            // N_k
  Eigen::Matrix<double, NF, DIM> first;          // dN_k / dxi_i
  Eigen::Matrix<double, NF, kNumSecond> second;  // d2N_k / dxi_i dxi_j
};

using BicubicValues = BasisValues<16, 2>;
using BrickValues = BasisValues<32, 3>;
using PlaneValues = BasisValues<8, 2>;

// Bicubic Hermite surface basis (16 functions).
struct BicubicHermite {
  static constexpr int kNumFunctions = 16;
  static constexpr int kNumNodes = 4;
  static constexpr int kParamsPerNode = 4;
  static BicubicValues evaluate(const Eigen::Vector2d& xi, unsigned updates);
  // d^(o1+o2) N_k / dxi1^o1 dxi2^o2 of the 16 functions at xi, for any o1, o2 in 0..3
  // (third derivatives: the fit's third-order penalty and edge jumps).
  static Eigen::Matrix<double, 16, 1> derivative(const Eigen::Vector2d& xi, int o1, int o2);
};

// Bicubic Hermite in (xi1, xi2) x linear Lagrange in xi3 (32 functions).
struct BicubicHermiteLinear {
  static constexpr int kNumFunctions = 32;
  static constexpr int kNumNodes = 8;
  static constexpr int kParamsPerNode = 4;
  static BrickValues evaluate(const Eigen::Vector3d& xi, unsigned updates);
};

// Cubic Hermite in xi1 x linear Lagrange in xi2 (8 functions).
struct CubicHermiteLinear {
  static constexpr int kNumFunctions = 8;
  static constexpr int kNumNodes = 4;
  static constexpr int kParamsPerNode = 2;
  static PlaneValues evaluate(const Eigen::Vector2d& xi, unsigned updates);
};

}  // namespace sf::basis
