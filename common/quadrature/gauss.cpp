#include "common/quadrature/gauss.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/core/types.hpp"

namespace sf::quadrature {

Rule1D gauss_legendre(int n) {
  if (n < 1 || n > 32) throw std::invalid_argument("gauss_legendre: n must be in 1..32, got " + std::to_string(n));
  Rule1D rule;
  rule.points.resize(n);
  rule.weights.resize(n);
  const double pi = sf::kPi;
  // Roots of P_n on [-1,1] by Newton from Chebyshev-like guesses, then map to [0,1].
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p1 = x, p0 = 1.0;
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // Recompute derivative at the converged root.
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = (n == 1) ? 1.0 : n * (x * p1 - p0) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    // x is the root near +1 for small i; store symmetric pair.
    rule.points[n - 1 - i] = 0.5 * (1.0 + x);
    rule.points[i] = 0.5 * (1.0 - x);
    rule.weights[n - 1 - i] = 0.5 * w;
    rule.weights[i] = 0.5 * w;
  }
  if (n % 2 == 1) rule.points[n / 2] = 0.5;
  return rule;
}

TensorRule<2> gauss_2d(int n1, int n2) {
  const Rule1D a = gauss_legendre(n1), b = gauss_legendre(n2);
  TensorRule<2> r;
  for (int j = 0; j < n2; ++j)
    for (int i = 0; i < n1; ++i) {
      r.points.emplace_back(a.points[i], b.points[j]);
      r.weights.push_back(a.weights[i] * b.weights[j]);
    }
  return r;
}

TensorRule<3> gauss_3d(int n1, int n2, int n3) {
  const Rule1D a = gauss_legendre(n1), b = gauss_legendre(n2), c = gauss_legendre(n3);
  TensorRule<3> r;
  for (int k = 0; k < n3; ++k)
    for (int j = 0; j < n2; ++j)
      for (int i = 0; i < n1; ++i) {
        r.points.emplace_back(a.points[i], b.points[j], c.points[k]);
        r.weights.push_back(a.weights[i] * b.weights[j] * c.weights[k]);
      }
  return r;
}

}  // namespace sf::quadrature
