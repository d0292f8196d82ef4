// Restarted GMRES and its helpers (common/linalg/krylov.hpp).
#include <gtest/gtest.h>

#include <Eigen/SparseLU>
#include <cmath>
#include <vector>

#include "common/linalg/krylov.hpp"

namespace sf::linalg {
namespace {

// A 2-D convection-diffusion operator on an m x m grid (unsymmetric, nonsingular).
SparseMatrix convection_diffusion(int m, double wind) {
  std::vector<Eigen::Triplet<double, int>> t;
  const auto id = [m](int i, int j) { return i * m + j; };
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      t.emplace_back(id(i, j), id(i, j), 4.0);
      if (i > 0) t.emplace_back(id(i, j), id(i - 1, j), -1.0 - wind);
      if (i + 1 < m) t.emplace_back(id(i, j), id(i + 1, j), -1.0 + wind);
      if (j > 0) t.emplace_back(id(i, j), id(i, j - 1), -1.0);
      if (j + 1 < m) t.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  SparseMatrix a(m * m, m * m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

TEST(Gmres, SolvesAnUnsymmetricSystemToTheToleranceAndAgreesWithLu) {
  const SparseMatrix a = convection_diffusion(30, 0.4);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
  Eigen::SparseLU<SparseMatrix> lu(a);
  const Eigen::VectorXd x_lu = lu.solve(b);
  // Preconditioner: the diagonal (Jacobi).
  const Eigen::VectorXd diag = a.diagonal();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(a.rows());
  GmresOptions o;
  o.restart = 30;  // forces restarts
  o.max_iterations = 2000;
  const GmresReport r = gmres(
      a, Storage::kFull,
      [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y) { y = v.cwiseQuotient(diag); }, b, x, o);
  EXPECT_TRUE(r.converged) << r.brief();
  EXPECT_GT(r.iterations, 30) << "the test should exercise a restart";
  EXPECT_LE(r.relative_residual, 1e-10);
  EXPECT_LT((a * x - b).norm(), 1.01e-10 * b.norm());
  EXPECT_LT((x - x_lu).norm(), 1e-8 * x_lu.norm());
}

TEST(Gmres, ReportsNoConvergenceWithinTheIterationLimit) {
  const SparseMatrix a = convection_diffusion(30, 0.4);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(a.rows());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(a.rows());
  GmresOptions o;
  o.max_iterations = 5;
  const GmresReport r = gmres(
      a, Storage::kFull, [](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y) { y = v; }, b, x, o);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 5);
  EXPECT_GT(r.relative_residual, 1e-10);
  EXPECT_NEAR(r.relative_residual, (a * x - b).norm() / b.norm(), 1e-12);
}

TEST(Gmres, LowerStorageMultipliesAsTheFullSymmetricMatrix) {
  SparseMatrix a = convection_diffusion(12, 0.0);  // symmetric
  a.coeffRef(3, 17) += 0.5;
  a.coeffRef(17, 3) += 0.5;
  const SparseMatrix lower = a.triangularView<Eigen::Lower>();
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(a.rows(), 0.5, -3.0);
  Eigen::VectorXd y;
  multiply(lower, Storage::kLower, v, y);
  EXPECT_LT((y - a * v).norm(), 1e-13 * (a * v).norm());
}

TEST(BlockDiagonal, KeepsOnlyEntriesWithinAGroup) {
  const SparseMatrix a = convection_diffusion(4, 0.2);  // 16 unknowns
  std::vector<int> group(16);
  for (int i = 0; i < 16; ++i) group[static_cast<std::size_t>(i)] = i / 8;
  const SparseMatrix m = block_diagonal(a, group);
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i)
      EXPECT_EQ(m.coeff(i, j),
                group[static_cast<std::size_t>(i)] == group[static_cast<std::size_t>(j)] ? a.coeff(i, j) : 0.0);
}

}  // namespace
}  // namespace sf::linalg
