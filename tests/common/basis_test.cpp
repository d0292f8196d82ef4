// Property tests of the element bases (common/basis/hermite.hpp): interpolation
// conditions, partition of unity, exact reproduction of the polynomial spaces the
// bases span, and every derivative against central finite differences.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/basis/hermite.hpp"
#include "common/core/types.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::basis {
namespace {

using test::kFdFirst;
using test::kFdSecond;
using test::kFdSecondStep;
using test::kFdStep;
using test::kPolynomialExact;
using test::kRoundoff;

template <class V>
std::string str(const V& v) {
  std::ostringstream os;
  os << "(";
  for (int i = 0; i < static_cast<int>(v.size()); ++i) os << (i ? ", " : "") << v[i];
  os << ")";
  return os.str();
}

// ---------------------------------------------------------------------------
// 1-D cubic Hermite and linear Lagrange

TEST(BasisCubicHermite, InterpolationConditionsAtBothEnds) {
  // expected[end][order][function]: H0 value at 0, H1 slope at 0, H2 value at 1, H3 slope at 1.
  const double expected[2][2][4] = {{{1, 0, 0, 0}, {0, 1, 0, 0}}, {{0, 0, 1, 0}, {0, 0, 0, 1}}};
  for (int end = 0; end < 2; ++end)
    for (int order = 0; order < 2; ++order) {
      const auto h = cubic_hermite(static_cast<double>(end), order);
      for (int f = 0; f < 4; ++f)
        EXPECT_NEAR(h[f], expected[end][order][f], kRoundoff)
            << "H" << f << " derivative order " << order << " at t=" << end;
    }
}

TEST(BasisCubicHermite, MatchesClosedFormsOfTheBrief) {
  std::mt19937 rng(test::kSeed);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (int s = 0; s < 20; ++s) {
    const double t = u(rng);
    const auto h = cubic_hermite(t, 0);
    const double ref[4] = {1 - 3 * t * t + 2 * t * t * t, t * (t - 1) * (t - 1), t * t * (3 - 2 * t), t * t * (t - 1)};
    for (int f = 0; f < 4; ++f) EXPECT_NEAR(h[f], ref[f], kRoundoff) << "H" << f << " at t=" << t;
  }
}

TEST(BasisCubicHermite, DerivativesMatchCentralDifferences) {
  std::mt19937 rng(test::kSeed + 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int s = 0; s < 25; ++s) {
    const double t = u(rng);
    for (int order = 1; order <= 3; ++order) {
      const auto analytic = cubic_hermite(t, order);
      const auto plus = cubic_hermite(t + kFdStep, order - 1);
      const auto minus = cubic_hermite(t - kFdStep, order - 1);
      for (int f = 0; f < 4; ++f)
        EXPECT_NEAR(analytic[f], (plus[f] - minus[f]) / (2 * kFdStep), kFdFirst)
            << "H" << f << " derivative order " << order << " at t=" << t;
    }
    // Second derivative straight from values (3-point stencil).
    const auto d2 = cubic_hermite(t, 2);
    const auto p = cubic_hermite(t + kFdSecondStep, 0), m = cubic_hermite(t - kFdSecondStep, 0),
               c = cubic_hermite(t, 0);
    for (int f = 0; f < 4; ++f)
      EXPECT_NEAR(d2[f], (p[f] - 2 * c[f] + m[f]) / (kFdSecondStep * kFdSecondStep), kFdSecond)
          << "H" << f << "'' from values at t=" << t;
  }
}

TEST(BasisCubicHermite, ReproducesEveryCubic) {
  std::mt19937 rng(test::kSeed + 2);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int s = 0; s < 10; ++s) {
    const double c0 = u(rng), c1 = u(rng), c2 = u(rng), c3 = u(rng);
    auto p = [&](double t) { return c0 + t * (c1 + t * (c2 + t * c3)); };
    auto dp = [&](double t) { return c1 + t * (2 * c2 + 3 * t * c3); };
    auto d2p = [&](double t) { return 2 * c2 + 6 * t * c3; };
    const double params[4] = {p(0), dp(0), p(1), dp(1)};
    for (int q = 0; q <= 10; ++q) {
      const double t = q / 10.0;
      double v[3] = {0, 0, 0};
      for (int order = 0; order < 3; ++order) {
        const auto h = cubic_hermite(t, order);
        for (int f = 0; f < 4; ++f) v[order] += params[f] * h[f];
      }
      EXPECT_NEAR(v[0], p(t), kPolynomialExact) << "value at t=" << t << ", sample " << s;
      EXPECT_NEAR(v[1], dp(t), kPolynomialExact) << "slope at t=" << t << ", sample " << s;
      EXPECT_NEAR(v[2], d2p(t), kPolynomialExact) << "curvature at t=" << t << ", sample " << s;
    }
  }
}

// The inline table (the fast path of projection and fitting) is the same polynomials:
// bit for bit what cubic_hermite() returns for every order, whatever order the table
// stops at.
TEST(BasisCubicHermite, TableIsCubicHermiteBitForBit) {
  std::mt19937 rng(test::kSeed + 3);
  std::uniform_real_distribution<double> u(-0.25, 1.25);
  for (int s = 0; s < 50; ++s) {
    const double t = s < 2 ? double(s) : u(rng);
    const CubicHermiteTable<3> t3 = cubic_hermite_table<3>(t);
    const CubicHermiteTable<2> t2 = cubic_hermite_table<2>(t);
    const CubicHermiteTable<0> t0 = cubic_hermite_table<0>(t);
    for (int order = 0; order <= 3; ++order) {
      const auto h = cubic_hermite(t, order);
      for (int f = 0; f < 4; ++f) {
        EXPECT_EQ(t3[order][f], h[f]) << "H" << f << " order " << order << " at t=" << t;
        if (order <= 2) {
          EXPECT_EQ(t2[order][f], h[f]) << "H" << f << " order " << order << " at t=" << t;
        }
      }
    }
    for (int f = 0; f < 4; ++f) EXPECT_EQ(t0[0][f], t3[0][f]) << "H" << f << " at t=" << t;
  }
  // Above the third derivative a cubic has none.
  for (double h : cubic_hermite(0.3, 4)) EXPECT_EQ(h, 0.0);
}

TEST(BasisLinearLagrange, InterpolationAndPartitionOfUnity) {
  for (int end = 0; end < 2; ++end) {
    const auto l = linear_lagrange(end, 0);
    for (int f = 0; f < 2; ++f) EXPECT_NEAR(l[f], f == end ? 1.0 : 0.0, kRoundoff) << "L" << f << " at t=" << end;
  }
  for (int q = 0; q <= 8; ++q) {
    const double t = -0.25 + q * 0.1875;
    const auto l = linear_lagrange(t, 0);
    const auto dl = linear_lagrange(t, 1);
    EXPECT_NEAR(l[0] + l[1], 1.0, kRoundoff) << "sum of values at t=" << t;
    EXPECT_NEAR(dl[0] + dl[1], 0.0, kRoundoff) << "sum of slopes at t=" << t;
    EXPECT_NEAR(l[1], t, kRoundoff) << "L1 reproduces t at t=" << t;
  }
}

TEST(BasisLinearLagrange, DerivativesMatchCentralDifferences) {
  std::mt19937 rng(test::kSeed + 3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int s = 0; s < 10; ++s) {
    const double t = u(rng);
    for (int order = 1; order <= 2; ++order) {
      const auto analytic = linear_lagrange(t, order);
      const auto plus = linear_lagrange(t + kFdStep, order - 1);
      const auto minus = linear_lagrange(t - kFdStep, order - 1);
      for (int f = 0; f < 2; ++f)
        EXPECT_NEAR(analytic[f], (plus[f] - minus[f]) / (2 * kFdStep), kFdFirst)
            << "L" << f << " derivative order " << order << " at t=" << t;
    }
  }
}

// ---------------------------------------------------------------------------
// Tensor bases, tested through one generic harness.
//
// Traits give, per basis: the dimension, the cell corner of local node n, the
// derivative multi-index that nodal parameter d interpolates, and the
// polynomial degree per direction of the space the basis spans.

template <class B>
struct Traits;

template <>
struct Traits<BicubicHermite> {
  static constexpr int kDim = 2;
  static constexpr std::array<int, 2> kDegree{{3, 3}};
  static std::array<int, 2> corner(int n) { return {n & 1, n >> 1}; }
  static std::array<int, 2> param_orders(int d) { return {d & 1, d >> 1}; }
  static const char* name() { return "BicubicHermite"; }
};

template <>
struct Traits<BicubicHermiteLinear> {
  static constexpr int kDim = 3;
  static constexpr std::array<int, 3> kDegree{{3, 3, 1}};
  static std::array<int, 3> corner(int n) { return {n & 1, (n >> 1) & 1, n >> 2}; }
  static std::array<int, 3> param_orders(int d) { return {d & 1, d >> 1, 0}; }
  static const char* name() { return "BicubicHermiteLinear"; }
};

template <>
struct Traits<CubicHermiteLinear> {
  static constexpr int kDim = 2;
  static constexpr std::array<int, 2> kDegree{{3, 1}};
  static std::array<int, 2> corner(int n) { return {n & 1, n >> 1}; }
  static std::array<int, 2> param_orders(int d) { return {d, 0}; }
  static const char* name() { return "CubicHermiteLinear"; }
};

template <int DIM>
using Point = Eigen::Matrix<double, DIM, 1>;

// Column of the second-derivative block for the pair (i, j), i <= j:
// 2-D (11, 12, 22); 3-D (11, 12, 13, 22, 23, 33).
template <int DIM>
int second_column(int i, int j) {
  if (i > j) std::swap(i, j);
  return i * DIM - i * (i - 1) / 2 + (j - i);
}

// Basis derivative of function k for a multi-index of total order <= 2.
template <class Values, int DIM>
double basis_derivative(const Values& b, int k, const std::array<int, DIM>& orders) {
  int total = 0;
  std::vector<int> dirs;
  for (int i = 0; i < DIM; ++i) {
    total += orders[i];
    for (int r = 0; r < orders[i]; ++r) dirs.push_back(i);
  }
  if (total == 0) return b.value[k];
  if (total == 1) return b.first(k, dirs[0]);
  return b.second(k, second_column<DIM>(dirs[0], dirs[1]));
}

// Tensor polynomial sum_c c_m prod x_i^{m_i} with m_i <= degree_i.
template <int DIM>
struct TensorPoly {
  std::array<int, DIM> degree;
  std::vector<double> coef;

  TensorPoly(const std::array<int, DIM>& deg, std::mt19937& rng) : degree(deg) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int n = 1;
    for (int i = 0; i < DIM; ++i) n *= degree[i] + 1;
    for (int m = 0; m < n; ++m) coef.push_back(u(rng));
  }
  static double mono(double x, int power, int order) {
    if (order > power) return 0.0;
    double f = 1.0;
    for (int r = 0; r < order; ++r) f *= power - r;
    return f * std::pow(x, power - order);
  }
  double operator()(const Point<DIM>& x, const std::array<int, DIM>& orders) const {
    double sum = 0.0;
    for (std::size_t m = 0; m < coef.size(); ++m) {
      int rest = static_cast<int>(m);
      double term = coef[m];
      for (int i = 0; i < DIM; ++i) {
        const int p = rest % (degree[i] + 1);
        rest /= degree[i] + 1;
        term *= mono(x[i], p, orders[i]);
      }
      sum += term;
    }
    return sum;
  }
};

// All derivative multi-indices of total order 0, 1, 2 (order 0 first).
template <int DIM>
std::vector<std::array<int, DIM>> multi_indices_up_to_2() {
  std::vector<std::array<int, DIM>> out;
  out.push_back({});
  for (int i = 0; i < DIM; ++i) {
    std::array<int, DIM> o{};
    o[i] = 1;
    out.push_back(o);
  }
  for (int i = 0; i < DIM; ++i)
    for (int j = i; j < DIM; ++j) {
      std::array<int, DIM> o{};
      ++o[i];
      ++o[j];
      out.push_back(o);
    }
  return out;
}

template <int DIM>
std::string orders_str(const std::array<int, DIM>& o) {
  std::string s = "d(";
  for (int i = 0; i < DIM; ++i) s += (i ? "," : "") + std::to_string(o[i]);
  return s + ")";
}

template <class B>
Point<Traits<B>::kDim> random_point(std::mt19937& rng, double lo = 0.02, double hi = 0.98) {
  std::uniform_real_distribution<double> u(lo, hi);
  Point<Traits<B>::kDim> x;
  for (int i = 0; i < x.size(); ++i) x[i] = u(rng);
  return x;
}

template <class B>
void check_partition_of_unity(unsigned seed) {
  constexpr int kDim = Traits<B>::kDim;
  std::mt19937 rng(seed);
  const auto all = kValues | kFirst | kSecond;
  for (int s = 0; s < 20; ++s) {
    const auto xi = random_point<B>(rng, -0.2, 1.2);
    const auto b = B::evaluate(xi, all);
    for (const auto& o : multi_indices_up_to_2<kDim>()) {
      double sum = 0.0;
      for (int n = 0; n < B::kNumNodes; ++n) sum += basis_derivative<decltype(b), kDim>(b, B::kParamsPerNode * n, o);
      const bool value = o == std::array<int, kDim>{};
      EXPECT_NEAR(sum, value ? 1.0 : 0.0, kRoundoff) << Traits<B>::name() << ": sum over nodes of the value functions, "
                                                     << orders_str<kDim>(o) << ", at xi=" << str(xi);
    }
  }
}

template <class B>
void check_interpolation_conditions() {
  constexpr int kDim = Traits<B>::kDim;
  for (int m = 0; m < B::kNumNodes; ++m) {
    const auto c = Traits<B>::corner(m);
    Point<kDim> xi;
    for (int i = 0; i < kDim; ++i) xi[i] = c[i];
    const auto b = B::evaluate(xi, kValues | kFirst | kSecond);
    for (int d = 0; d < B::kParamsPerNode; ++d) {
      const auto o = Traits<B>::param_orders(d);
      for (int k = 0; k < B::kNumFunctions; ++k) {
        const double expected = k == B::kParamsPerNode * m + d ? 1.0 : 0.0;
        EXPECT_NEAR((basis_derivative<decltype(b), kDim>(b, k, o)), expected, kRoundoff)
            << Traits<B>::name() << ": function " << k << ", parameter " << d << " (" << orders_str<kDim>(o)
            << ") at node " << m << " xi=" << str(xi);
      }
    }
  }
}

template <class B>
void check_reproduction(unsigned seed) {
  constexpr int kDim = Traits<B>::kDim;
  std::mt19937 rng(seed);
  for (int s = 0; s < 5; ++s) {
    const TensorPoly<kDim> p(Traits<B>::kDegree, rng);
    // Nodal parameters: the derivatives of p the basis interpolates, at each node.
    std::vector<double> u(B::kNumFunctions);
    for (int n = 0; n < B::kNumNodes; ++n) {
      const auto c = Traits<B>::corner(n);
      Point<kDim> xn;
      for (int i = 0; i < kDim; ++i) xn[i] = c[i];
      for (int d = 0; d < B::kParamsPerNode; ++d) u[B::kParamsPerNode * n + d] = p(xn, Traits<B>::param_orders(d));
    }
    for (int q = 0; q < 10; ++q) {
      const auto xi = random_point<B>(rng);
      const auto b = B::evaluate(xi, kValues | kFirst | kSecond);
      for (const auto& o : multi_indices_up_to_2<kDim>()) {
        double v = 0.0;
        for (int k = 0; k < B::kNumFunctions; ++k) v += u[k] * basis_derivative<decltype(b), kDim>(b, k, o);
        EXPECT_NEAR(v, p(xi, o), kPolynomialExact)
            << Traits<B>::name() << ": " << orders_str<kDim>(o) << " of a random polynomial of degree "
            << str(Traits<B>::kDegree) << " at xi=" << str(xi) << " (sample " << s << ")";
      }
    }
  }
}

template <class B>
void check_finite_differences(unsigned seed) {
  constexpr int kDim = Traits<B>::kDim;
  std::mt19937 rng(seed);
  const auto all = kValues | kFirst | kSecond;
  for (int s = 0; s < 10; ++s) {
    const auto xi = random_point<B>(rng);
    const auto b = B::evaluate(xi, all);
    for (int i = 0; i < kDim; ++i) {
      const Point<kDim> ei = Point<kDim>::Unit(i);
      // First derivatives from values.
      const auto bp = B::evaluate(xi + kFdStep * ei, all), bm = B::evaluate(xi - kFdStep * ei, all);
      for (int k = 0; k < B::kNumFunctions; ++k) {
        EXPECT_NEAR(b.first(k, i), (bp.value[k] - bm.value[k]) / (2 * kFdStep), kFdFirst)
            << Traits<B>::name() << ": dN" << k << "/dxi" << i + 1 << " at xi=" << str(xi);
        // Second derivatives from the analytic first derivatives.
        for (int j = 0; j < kDim; ++j)
          EXPECT_NEAR(b.second(k, second_column<kDim>(i, j)), (bp.first(k, j) - bm.first(k, j)) / (2 * kFdStep),
                      kFdFirst)
              << Traits<B>::name() << ": d2N" << k << "/dxi" << i + 1 << "dxi" << j + 1
              << " vs FD of first derivatives at xi=" << str(xi);
      }
      // Second derivatives straight from values.
      for (int j = i; j < kDim; ++j) {
        const Point<kDim> ej = Point<kDim>::Unit(j);
        const double h = kFdSecondStep;
        for (int k = 0; k < B::kNumFunctions; ++k) {
          double fd;
          if (i == j) {
            fd = (B::evaluate(xi + h * ei, kValues).value[k] - 2 * b.value[k] +
                  B::evaluate(xi - h * ei, kValues).value[k]) /
                 (h * h);
          } else {
            fd = (B::evaluate(xi + h * ei + h * ej, kValues).value[k] -
                  B::evaluate(xi + h * ei - h * ej, kValues).value[k] -
                  B::evaluate(xi - h * ei + h * ej, kValues).value[k] +
                  B::evaluate(xi - h * ei - h * ej, kValues).value[k]) /
                 (4 * h * h);
          }
          EXPECT_NEAR(b.second(k, second_column<kDim>(i, j)), fd, kFdSecond)
              << Traits<B>::name() << ": d2N" << k << "/dxi" << i + 1 << "dxi" << j + 1
              << " vs FD of values at xi=" << str(xi);
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Bicubic Hermite (16)

TEST(BasisBicubic, PartitionOfUnity) { check_partition_of_unity<BicubicHermite>(test::kSeed + 10); }

TEST(BasisBicubic, InterpolationConditionsAtCorners) { check_interpolation_conditions<BicubicHermite>(); }

TEST(BasisBicubic, ReproducesBicubicPolynomials) { check_reproduction<BicubicHermite>(test::kSeed + 11); }

TEST(BasisBicubic, DerivativesMatchFiniteDifferences) { check_finite_differences<BicubicHermite>(test::kSeed + 12); }

TEST(BasisBicubic, IsTensorProductInDocumentedOrder) {
  // Function k = 4n + d with n = a + 2b, d = k1 + 2 k2 is H_{2a+k1}(xi1) H_{2b+k2}(xi2).
  std::mt19937 rng(test::kSeed + 13);
  for (int s = 0; s < 10; ++s) {
    const Vec2 xi = random_point<BicubicHermite>(rng);
    const auto b = BicubicHermite::evaluate(xi, kValues);
    const auto h1 = cubic_hermite(xi[0], 0), h2 = cubic_hermite(xi[1], 0);
    for (int k = 0; k < 16; ++k) {
      const int n = k / 4, d = k % 4, a = n & 1, bb = n >> 1;
      EXPECT_NEAR(b.value[k], h1[2 * a + (d & 1)] * h2[2 * bb + (d >> 1)], kRoundoff)
          << "function " << k << " at xi=" << str(xi);
    }
  }
}

// derivative(xi, o1, o2): the same numbers as evaluate() up to second order, and third
// derivatives (which evaluate() does not give) against central differences of second ones.
TEST(BasisBicubic, DerivativeOfAnyOrderUpToThree) {
  std::mt19937 rng(test::kSeed + 14);
  for (int s = 0; s < 10; ++s) {
    const Vec2 xi = random_point<BicubicHermite>(rng);
    const auto b = BicubicHermite::evaluate(xi, kValues | kFirst | kSecond);
    const std::pair<int, int> orders[] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
    const Eigen::Matrix<double, 16, 1> expected[] = {b.value,         b.first.col(0),  b.first.col(1),
                                                     b.second.col(0), b.second.col(1), b.second.col(2)};
    for (int q = 0; q < 6; ++q) {
      const Eigen::Matrix<double, 16, 1> d = BicubicHermite::derivative(xi, orders[q].first, orders[q].second);
      for (int k = 0; k < 16; ++k)
        EXPECT_NEAR(d[k], expected[q][k], kRoundoff)
            << "function " << k << " order (" << orders[q].first << "," << orders[q].second << ") at " << str(xi);
    }
    for (int o1 = 0; o1 <= 3; ++o1) {
      const int o2 = 3 - o1;  // (3,0) (2,1) (1,2) (0,3): differentiate a second derivative once more
      const int dir = o1 > 0 ? 0 : 1;
      const Vec2 step = dir == 0 ? Vec2(kFdStep, 0) : Vec2(0, kFdStep);
      const int l1 = o1 - (dir == 0), l2 = o2 - (dir == 1);
      const Eigen::Matrix<double, 16, 1> fd =
          (BicubicHermite::derivative(xi + step, l1, l2) - BicubicHermite::derivative(xi - step, l1, l2)) /
          (2 * kFdStep);
      const Eigen::Matrix<double, 16, 1> d = BicubicHermite::derivative(xi, o1, o2);
      for (int k = 0; k < 16; ++k)
        EXPECT_NEAR(d[k], fd[k], kFdFirst) << "function " << k << " order (" << o1 << "," << o2 << ") at " << str(xi);
    }
  }
  // Fourth derivatives in one direction vanish (cubic in each variable).
  EXPECT_EQ(BicubicHermite::derivative(Vec2(0.2, 0.6), 4, 0).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BasisBicubic, RecordsRequestedUpdates) {
  const Vec2 xi(0.3, 0.7);
  for (unsigned flags : {unsigned(kValues), unsigned(kFirst), unsigned(kSecond), unsigned(kValues | kSecond),
                         unsigned(kValues | kFirst | kSecond)}) {
    EXPECT_EQ(BicubicHermite::evaluate(xi, flags).updated, flags) << "flags " << flags;
    EXPECT_EQ(BicubicHermiteLinear::evaluate(Vec3(0.3, 0.7, 0.2), flags).updated, flags) << "flags " << flags;
    EXPECT_EQ(CubicHermiteLinear::evaluate(xi, flags).updated, flags) << "flags " << flags;
  }
  // Asking for second derivatives alone gives the same numbers as asking for all.
  const auto all = BicubicHermite::evaluate(xi, kValues | kFirst | kSecond);
  const auto only2 = BicubicHermite::evaluate(xi, kSecond);
  for (int k = 0; k < 16; ++k)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(only2.second(k, c), all.second(k, c), kRoundoff) << "function " << k << " column " << c;
}

// ---------------------------------------------------------------------------
// Bicubic Hermite x linear (32)

TEST(BasisBicubicHermiteLinear, PartitionOfUnity) { check_partition_of_unity<BicubicHermiteLinear>(test::kSeed + 20); }

TEST(BasisBicubicHermiteLinear, InterpolationConditionsAtNodes) {
  check_interpolation_conditions<BicubicHermiteLinear>();
}

TEST(BasisBicubicHermiteLinear, ReproducesBicubicTimesLinear) {
  check_reproduction<BicubicHermiteLinear>(test::kSeed + 21);
}

TEST(BasisBicubicHermiteLinear, DerivativesMatchFiniteDifferences) {
  check_finite_differences<BicubicHermiteLinear>(test::kSeed + 22);
}

TEST(BasisBicubicHermiteLinear, FacesAreTheBicubicBasis) {
  std::mt19937 rng(test::kSeed + 23);
  for (int s = 0; s < 10; ++s) {
    const Vec2 xi = random_point<BicubicHermite>(rng);
    const auto q = BicubicHermite::evaluate(xi, kValues | kFirst | kSecond);
    for (int c = 0; c < 2; ++c) {
      const auto b = BicubicHermiteLinear::evaluate(Vec3(xi[0], xi[1], c), kValues | kFirst | kSecond);
      for (int k = 0; k < 32; ++k) {
        const bool on_face = (k / 16) == c;
        const int k2 = k % 16;
        const std::string where =
            "function " + std::to_string(k) + " on face xi3=" + std::to_string(c) + " at xi=" + str(xi);
        EXPECT_NEAR(b.value[k], on_face ? q.value[k2] : 0.0, kRoundoff) << where;
        EXPECT_NEAR(b.first(k, 0), on_face ? q.first(k2, 0) : 0.0, kRoundoff) << where;
        EXPECT_NEAR(b.first(k, 1), on_face ? q.first(k2, 1) : 0.0, kRoundoff) << where;
        EXPECT_NEAR(b.second(k, 0), on_face ? q.second(k2, 0) : 0.0, kRoundoff) << where;
        EXPECT_NEAR(b.second(k, 1), on_face ? q.second(k2, 1) : 0.0, kRoundoff) << where;
        EXPECT_NEAR(b.second(k, 3), on_face ? q.second(k2, 2) : 0.0, kRoundoff) << where;
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Cubic Hermite x linear (8)

TEST(BasisCubicHermiteLinear, PartitionOfUnity) { check_partition_of_unity<CubicHermiteLinear>(test::kSeed + 30); }

TEST(BasisCubicHermiteLinear, InterpolationConditionsAtNodes) { check_interpolation_conditions<CubicHermiteLinear>(); }

TEST(BasisCubicHermiteLinear, ReproducesCubicTimesLinear) { check_reproduction<CubicHermiteLinear>(test::kSeed + 31); }

TEST(BasisCubicHermiteLinear, DerivativesMatchFiniteDifferences) {
  check_finite_differences<CubicHermiteLinear>(test::kSeed + 32);
}

}  // namespace
}  // namespace sf::basis
