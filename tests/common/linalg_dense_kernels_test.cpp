// Lower-triangle products of common/linalg/dense_kernels.hpp against a plain triple loop,
// on every instruction set this processor has: add_atb_lower (C +=), set_atb_lower
// (C =, over a C full of garbage) and set_atb_lower_packed (operands in 8-row strips), for
// sizes that take every block shape (whole register blocks, the leftover vectors at the
// diagonal, the scalar fallback) and depths that are not multiples of anything.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/linalg/dense_kernels.hpp"

namespace sf::linalg {
namespace {

struct Operands {
  int n, depth;
  std::vector<double> a, b;  // depth rows of n (row p at p n)
};

Operands random_operands(std::mt19937& rng, int n, int depth) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Operands o{n, depth, std::vector<double>(static_cast<std::size_t>(n) * depth),
             std::vector<double>(static_cast<std::size_t>(n) * depth)};
  for (double& v : o.a) v = u(rng);
  for (double& v : o.b) v = u(rng);
  return o;
}

// C(i, j) = sum_p A(p, i) B(p, j), the whole matrix.
std::vector<double> plain_product(const Operands& o) {
  std::vector<double> c(static_cast<std::size_t>(o.n) * o.n, 0.0);
  for (int j = 0; j < o.n; ++j)
    for (int i = 0; i < o.n; ++i) {
      double s = 0.0;
      for (int p = 0; p < o.depth; ++p) s += o.a[p * o.n + i] * o.b[p * o.n + j];
      c[static_cast<std::size_t>(j) * o.n + i] = s;
    }
  return c;
}

// Largest difference on the lower triangle, relative to the depth (entries are sums of
// `depth` products of numbers below 1).
double lower_difference(const std::vector<double>& x, const std::vector<double>& y, int n, int depth) {
  double worst = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i)
      worst = std::max(worst, std::abs(x[static_cast<std::size_t>(j) * n + i] - y[static_cast<std::size_t>(j) * n + i]));
  return worst / depth;
}

class EveryIsa : public ::testing::Test {
 protected:
  void TearDown() override { set_kernel_isa(saved_); }
  KernelIsa saved_ = kernel_isa();
};

TEST_F(EveryIsa, LowerProductsMatchThePlainLoop) {
  std::mt19937 rng(20261203);
  for (int isa = 0; isa <= static_cast<int>(best_kernel_isa()); ++isa) {
    set_kernel_isa(static_cast<KernelIsa>(isa));
    for (int n : {2, 6, 8, 12, 13, 16, 24, 32, 40, 48, 96})
      for (int depth : {1, 7, 96, 193}) {
        const Operands o = random_operands(rng, n, depth);
        const std::vector<double> want = plain_product(o);
        // C += A^T B onto a known C.
        std::vector<double> c(want.size(), 1.0), want_plus(want);
        for (double& v : want_plus) v += 1.0;
        add_atb_lower(n, depth, o.a.data(), n, o.b.data(), n, c.data(), n);
        EXPECT_LT(lower_difference(c, want_plus, n, depth), 1e-15)
            << "add_atb_lower " << to_string(kernel_isa()) << " n " << n << " depth " << depth;
        // C = A^T B over garbage.
        std::fill(c.begin(), c.end(), std::nan(""));
        set_atb_lower(n, depth, o.a.data(), n, o.b.data(), n, c.data(), n);
        EXPECT_LT(lower_difference(c, want, n, depth), 1e-15)
            << "set_atb_lower " << to_string(kernel_isa()) << " n " << n << " depth " << depth;
        if (n % 8 != 0) {
          EXPECT_THROW(set_atb_lower_packed(n, depth, o.a.data(), o.b.data(), c.data(), n), std::invalid_argument);
          continue;
        }
        std::vector<double> ap(o.a.size()), bp(o.b.size());
        for (int p = 0; p < depth; ++p)
          for (int i = 0; i < n; ++i) {
            ap[static_cast<std::size_t>(packed_index(depth, p, i))] = o.a[p * n + i];
            bp[static_cast<std::size_t>(packed_index(depth, p, i))] = o.b[p * n + i];
          }
        std::fill(c.begin(), c.end(), std::nan(""));
        set_atb_lower_packed(n, depth, ap.data(), bp.data(), c.data(), n);
        EXPECT_LT(lower_difference(c, want, n, depth), 1e-15)
            << "set_atb_lower_packed " << to_string(kernel_isa()) << " n " << n << " depth " << depth;
        // The packed and unpacked forms add the same products in the same order.
        std::vector<double> c2(want.size(), std::nan(""));
        set_atb_lower(n, depth, o.a.data(), n, o.b.data(), n, c2.data(), n);
        EXPECT_EQ(lower_difference(c, c2, n, depth), 0.0) << to_string(kernel_isa()) << " n " << n;
      }
  }
}

}  // namespace
}  // namespace sf::linalg
