// Property tests of Gauss-Legendre quadrature on [0,1] and its tensor rules
// (common/quadrature/gauss.hpp): exactness up to degree 2n-1, the exact error
// constant at degree 2n, weights, symmetry, and tensor products.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "common/quadrature/gauss.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::quadrature {
namespace {

using test::kQuadratureErrorConstantRel;
using test::kQuadratureExact;
using test::kRoundoff;

double integrate_monomial(const Rule1D& rule, int k) {
  double q = 0.0;
  for (std::size_t i = 0; i < rule.points.size(); ++i) q += rule.weights[i] * std::pow(rule.points[i], k);
  return q;
}

// Error of the n-point rule on [0,1] for t^(2n): integral - rule
// = (n!)^4 / ((2n+1) ((2n)!)^2)  (the Gauss error term with f^(2n) = (2n)!).
double gauss_error_constant(int n) {
  const double log_e = 4.0 * std::lgamma(n + 1.0) - std::log(2.0 * n + 1.0) - 2.0 * std::lgamma(2.0 * n + 1.0);
  return std::exp(log_e);
}

TEST(QuadratureGaussLegendre, IntegratesMonomialsUpToDegree2nMinus1Exactly) {
  for (int n = 1; n <= 32; ++n) {
    const Rule1D rule = gauss_legendre(n);
    ASSERT_EQ(static_cast<int>(rule.points.size()), n);
    ASSERT_EQ(static_cast<int>(rule.weights.size()), n);
    for (int k = 0; k <= 2 * n - 1; ++k)
      EXPECT_NEAR(integrate_monomial(rule, k), 1.0 / (k + 1), kQuadratureExact)
          << n << "-point rule, integral of t^" << k;
  }
}

TEST(QuadratureGaussLegendre, MissesDegree2nByTheGaussErrorConstant) {
  for (int n = 1; n <= 10; ++n) {
    const Rule1D rule = gauss_legendre(n);
    const int k = 2 * n;
    const double error = 1.0 / (k + 1) - integrate_monomial(rule, k);
    const double expected = gauss_error_constant(n);
    // Nonzero, with the right sign and size: not exact, and not roundoff.
    EXPECT_GT(error, 0.5 * expected) << n << "-point rule must NOT integrate t^" << k << " exactly";
    EXPECT_NEAR(error, expected, kQuadratureErrorConstantRel * expected) << n << "-point rule, error for t^" << k;
  }
}

TEST(QuadratureGaussLegendre, WeightsArePositiveAndSumToOne) {
  for (int n = 1; n <= 32; ++n) {
    const Rule1D rule = gauss_legendre(n);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      EXPECT_GT(rule.weights[i], 0.0) << n << "-point rule, weight " << i;
      sum += rule.weights[i];
    }
    EXPECT_NEAR(sum, 1.0, kQuadratureExact) << n << "-point rule, sum of weights";
  }
}

TEST(QuadratureGaussLegendre, PointsAreSymmetricAscendingAndInside) {
  for (int n = 1; n <= 32; ++n) {
    const Rule1D rule = gauss_legendre(n);
    for (int i = 0; i < n; ++i) {
      EXPECT_GT(rule.points[i], 0.0) << n << "-point rule, point " << i;
      EXPECT_LT(rule.points[i], 1.0) << n << "-point rule, point " << i;
      if (i + 1 < n) {
        EXPECT_LT(rule.points[i], rule.points[i + 1]) << n << "-point rule, points " << i << ", " << i + 1;
      }
      EXPECT_NEAR(rule.points[i] + rule.points[n - 1 - i], 1.0, kRoundoff)
          << n << "-point rule, symmetry of points " << i << " and " << n - 1 - i;
      EXPECT_NEAR(rule.weights[i], rule.weights[n - 1 - i], kRoundoff)
          << n << "-point rule, symmetry of weights " << i << " and " << n - 1 - i;
    }
    if (n % 2 == 1) {
      EXPECT_NEAR(rule.points[n / 2], 0.5, kRoundoff) << n << "-point rule, middle point";
    }
  }
}

TEST(QuadratureGaussLegendre, PointsAreRootsOfTheLegendrePolynomial) {
  for (int n = 1; n <= 32; ++n) {
    const Rule1D rule = gauss_legendre(n);
    for (int i = 0; i < n; ++i) {
      const double x = 2.0 * rule.points[i] - 1.0;
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      EXPECT_NEAR(p1, 0.0, kRoundoff) << "P_" << n << " at point " << i << " (x=" << x << ")";
    }
  }
}

TEST(QuadratureGaussLegendre, RejectsSizesOutsideTheTable) {
  EXPECT_THROW(gauss_legendre(0), std::invalid_argument);
  EXPECT_THROW(gauss_legendre(-3), std::invalid_argument);
  EXPECT_THROW(gauss_legendre(33), std::invalid_argument);
  EXPECT_NO_THROW(gauss_legendre(32));
}

TEST(QuadratureTensor, TwoDimensionalRuleIsExactForProductsUpToDegree2nMinus1) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {3, 2}, {4, 4}, {5, 2}, {6, 6}};
  for (const auto& s : sizes) {
    const int n1 = s[0], n2 = s[1];
    const TensorRule<2> rule = gauss_2d(n1, n2);
    ASSERT_EQ(rule.size(), n1 * n2);
    ASSERT_EQ(static_cast<int>(rule.points.size()), n1 * n2);
    for (int i = 0; i <= 2 * n1; ++i)
      for (int j = 0; j <= 2 * n2 - 1; ++j) {
        double q = 0.0;
        for (int p = 0; p < rule.size(); ++p)
          q += rule.weights[p] * std::pow(rule.points[p][0], i) * std::pow(rule.points[p][1], j);
        const double exact = 1.0 / ((i + 1.0) * (j + 1.0));
        if (i <= 2 * n1 - 1) {
          EXPECT_NEAR(q, exact, kQuadratureExact) << n1 << "x" << n2 << " rule, xi1^" << i << " xi2^" << j;
        } else {
          // Degree 2 n1 in xi1: error = error constant times the exact xi2 integral.
          const double expected = gauss_error_constant(n1) / (j + 1.0);
          EXPECT_NEAR(exact - q, expected, kQuadratureErrorConstantRel * expected)
              << n1 << "x" << n2 << " rule must miss xi1^" << i << " xi2^" << j;
        }
      }
  }
}

TEST(QuadratureTensor, ThreeDimensionalRuleIsExactForProductsUpToDegree2nMinus1) {
  const int sizes[][3] = {{1, 1, 1}, {2, 3, 2}, {3, 2, 4}, {4, 4, 4}};
  for (const auto& s : sizes) {
    const int n1 = s[0], n2 = s[1], n3 = s[2];
    const TensorRule<3> rule = gauss_3d(n1, n2, n3);
    ASSERT_EQ(rule.size(), n1 * n2 * n3);
    double sum = 0.0;
    for (double w : rule.weights) sum += w;
    EXPECT_NEAR(sum, 1.0, kQuadratureExact) << n1 << "x" << n2 << "x" << n3 << " rule, sum of weights";
    for (int i = 0; i <= 2 * n1 - 1; ++i)
      for (int j = 0; j <= 2 * n2 - 1; ++j)
        for (int k = 0; k <= 2 * n3 - 1; ++k) {
          double q = 0.0;
          for (int p = 0; p < rule.size(); ++p)
            q += rule.weights[p] * std::pow(rule.points[p][0], i) * std::pow(rule.points[p][1], j) *
                 std::pow(rule.points[p][2], k);
          EXPECT_NEAR(q, 1.0 / ((i + 1.0) * (j + 1.0) * (k + 1.0)), kQuadratureExact)
              << n1 << "x" << n2 << "x" << n3 << " rule, xi1^" << i << " xi2^" << j << " xi3^" << k;
        }
    // One degree too many in xi3 is missed.
    double q = 0.0;
    for (int p = 0; p < rule.size(); ++p) q += rule.weights[p] * std::pow(rule.points[p][2], 2 * n3);
    const double expected = gauss_error_constant(n3);
    EXPECT_NEAR(1.0 / (2 * n3 + 1) - q, expected, kQuadratureErrorConstantRel * expected)
        << n1 << "x" << n2 << "x" << n3 << " rule must miss xi3^" << 2 * n3;
  }
}

TEST(QuadratureTensor, PointsRunXi1FastestWithProductWeights) {
  const Rule1D a = gauss_legendre(3), b = gauss_legendre(2), c = gauss_legendre(4);
  const TensorRule<2> r2 = gauss_2d(3, 2);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i) {
      const int p = i + 3 * j;
      EXPECT_NEAR(r2.points[p][0], a.points[i], kRoundoff) << "2-D point " << p << " xi1";
      EXPECT_NEAR(r2.points[p][1], b.points[j], kRoundoff) << "2-D point " << p << " xi2";
      EXPECT_NEAR(r2.weights[p], a.weights[i] * b.weights[j], kRoundoff) << "2-D weight " << p;
    }
  const TensorRule<3> r3 = gauss_3d(3, 2, 4);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const int p = i + 3 * (j + 2 * k);
        EXPECT_NEAR(r3.points[p][0], a.points[i], kRoundoff) << "3-D point " << p << " xi1";
        EXPECT_NEAR(r3.points[p][1], b.points[j], kRoundoff) << "3-D point " << p << " xi2";
        EXPECT_NEAR(r3.points[p][2], c.points[k], kRoundoff) << "3-D point " << p << " xi3";
        EXPECT_NEAR(r3.weights[p], a.weights[i] * b.weights[j] * c.weights[k], kRoundoff) << "3-D weight " << p;
      }
}

}  // namespace
}  // namespace sf::quadrature
