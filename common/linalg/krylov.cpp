#include "common/linalg/krylov.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "common/core/error.hpp"

namespace sf::linalg {

std::string GmresReport::brief() const {
  return fmt::format("gmres: {} in {} iterations, |r|/|b| {:.2g}, {:.3g} s", converged ? "converged" : "not converged",
                     iterations, relative_residual, seconds);
}

void multiply(const SparseMatrix& a, Storage storage, const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y) {
  if (storage == Storage::kFull) {
    y.noalias() = a * v;
    return;
  }
  // Lower triangle of a symmetric A: y = L v + L^T v - diag v, one pass over the columns.
  y.setZero(a.rows());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  for (Index j = 0; j < a.cols(); ++j) {
    const double vj = v(j);
    double dot = 0.0;
    for (int p = outer[j]; p < outer[j + 1]; ++p) {
      const int i = inner[p];
      y(i) += val[p] * vj;
      if (i != j) dot += val[p] * v(i);
    }
    y(j) += dot;
  }
}

GmresReport gmres(const SparseMatrix& a, Storage storage, const PreconditionerApply& precondition,
                  const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::VectorXd& x, const GmresOptions& options) {
  SF_ASSERT(a.rows() == a.cols() && b.size() == a.rows() && x.size() == a.rows(), "gmres: sizes differ");
  SF_ASSERT(options.restart >= 1 && options.max_iterations >= 1, "gmres: restart and max_iterations >= 1");
  const auto t0 = std::chrono::steady_clock::now();
  GmresReport report;
  const Index n = a.rows();
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x.setZero();
    report.converged = true;
    return report;
  }
  const int m = options.restart;
  const double target = options.tolerance * b_norm;
  Eigen::MatrixXd v(n, m + 1);  // Krylov basis
  Eigen::MatrixXd z(n, m);      // M^-1 v_j (flexible form: x += Z y)
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1), w(n), r(n);
  multiply(a, storage, x, r);
  r = b - r;
  double r_norm = r.norm();
  while (r_norm > target && report.iterations < options.max_iterations) {
    v.col(0) = r / r_norm;
    g.setZero();
    g(0) = r_norm;
    int k = 0;
    for (; k < m && report.iterations < options.max_iterations; ++k) {
      Eigen::VectorXd zk(n);
      precondition(v.col(k), zk);
      z.col(k) = zk;
      multiply(a, storage, zk, w);
      ++report.iterations;
      for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
        h(i, k) = v.col(i).dot(w);
        w -= h(i, k) * v.col(i);
      }
      h(k + 1, k) = w.norm();
      if (h(k + 1, k) > 0.0) v.col(k + 1) = w / h(k + 1, k);
      for (int i = 0; i < k; ++i) {  // earlier rotations
        const double t = cs(i) * h(i, k) + sn(i) * h(i + 1, k);
        h(i + 1, k) = -sn(i) * h(i, k) + cs(i) * h(i + 1, k);
        h(i, k) = t;
      }
      const double d = std::hypot(h(k, k), h(k + 1, k));
      cs(k) = d > 0.0 ? h(k, k) / d : 1.0;
      sn(k) = d > 0.0 ? h(k + 1, k) / d : 0.0;
      h(k, k) = d;
      h(k + 1, k) = 0.0;
      g(k + 1) = -sn(k) * g(k);
      g(k) = cs(k) * g(k);
      if (std::abs(g(k + 1)) <= target || h(k, k) == 0.0) {
        ++k;
        break;
      }
    }
    // x += Z y with H y = g (upper triangular k x k).
    const Eigen::VectorXd y = h.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    x.noalias() += z.leftCols(k) * y;
    multiply(a, storage, x, r);  // the true residual (guards against drift in the recurrence)
    r = b - r;
    const double previous = r_norm;
    r_norm = r.norm();
    if (!(r_norm < previous)) break;  // stagnation (or NaN): give up, the caller decides
  }
  report.relative_residual = r_norm / b_norm;
  report.converged = r_norm <= target;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

SparseMatrix block_diagonal(const SparseMatrix& a, const std::vector<int>& group) {
  SF_ASSERT(static_cast<Index>(group.size()) == a.rows() && a.rows() == a.cols(), "one group per row");
  SparseMatrix out(a.rows(), a.cols());
  Index nnz = 0;
  for (Index j = 0; j < a.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it)
      if (group[static_cast<std::size_t>(it.row())] == group[static_cast<std::size_t>(j)]) ++nnz;
  std::vector<Eigen::Triplet<double, int>> t;
  t.reserve(static_cast<std::size_t>(nnz));
  for (Index j = 0; j < a.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it)
      if (group[static_cast<std::size_t>(it.row())] == group[static_cast<std::size_t>(j)])
        t.emplace_back(static_cast<int>(it.row()), static_cast<int>(j), it.value());
  out.setFromTriplets(t.begin(), t.end());
  out.makeCompressed();
  return out;
}

}  // namespace sf::linalg
