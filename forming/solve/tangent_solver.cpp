#include "forming/solve/tangent_solver.hpp"

#include "common/core/error.hpp"

namespace sf::forming {

TangentSolver::TangentSolver(linalg::SolverKind kind, bool unsymmetric) {
  const bool try_cholesky = kind == linalg::SolverKind::kAuto && !unsymmetric &&
                            linalg::solver_available(linalg::SolverKind::kCholmod);
  if (try_cholesky)
    spd_ = std::make_unique<linalg::LinearSolver>(linalg::SolverKind::kCholmod,
                                                  linalg::MatrixProperty::kSymmetricPositiveDefinite);
  general_ = std::make_unique<linalg::LinearSolver>(
      kind, unsymmetric ? linalg::MatrixProperty::kUnsymmetric : linalg::MatrixProperty::kSymmetricIndefinite);
}

const linalg::SolveReport& TangentSolver::factorize(const linalg::SparseMatrix& k) {
  if (spd_ && skip_cholesky_ > 0) {
    --skip_cholesky_;
  } else if (spd_) {
    const linalg::SolveReport& r = spd_->factorize(k);
    if (r.ok()) {
      active_ = spd_.get();
      return r;
    }
    skip_cholesky_ = 4;
  }
  const linalg::SolveReport& r = general_->factorize(k);
  active_ = r.ok() ? general_.get() : nullptr;
  return r;
}

Eigen::MatrixXd TangentSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const {
  SF_ASSERT(active_ != nullptr, "TangentSolver::solve() needs a successful factorize()");
  return active_->solve(b);
}

FreeDofs::FreeDofs(const std::vector<bool>& is_free) {
  const Index n = static_cast<Index>(is_free.size());
  for (Index d = 0; d < n; ++d)
    if (is_free[static_cast<std::size_t>(d)]) index.push_back(d);
  select.resize(n, size());
  std::vector<Eigen::Triplet<double, int>> t;
  t.reserve(index.size());
  for (Index j = 0; j < size(); ++j) t.emplace_back(static_cast<int>(index[j]), static_cast<int>(j), 1.0);
  select.setFromTriplets(t.begin(), t.end());
}

VecX FreeDofs::restrict(const VecX& v) const {
  VecX out(size());
  for (Index j = 0; j < size(); ++j) out(j) = v(index[j]);
  return out;
}

}  // namespace sf::forming
