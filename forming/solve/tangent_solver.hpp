#pragma once
// Pieces of a Newton iteration shared by the static, dynamic and arc-length solvers:
// the free dofs of a solve (and the selection matrix that restricts a tangent to them)
// and the linear solver of the Newton tangent.
#include <memory>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::forming {

// The free dofs of a solve, in ascending order, and the n x nf selection matrix S
// (column j = unit vector of free dof j): K_ff = S^T K S, x += S dx_f.
struct FreeDofs {
  std::vector<Index> index;
  linalg::SparseMatrix select;
  FreeDofs() = default;
  explicit FreeDofs(const std::vector<bool>& is_free);
  Index size() const { return static_cast<Index>(index.size()); }
  VecX restrict(const VecX& v) const;  // the free entries of v (n_dofs)
};

// Linear solves with a Newton tangent. With kAuto and a symmetric tangent: Cholesky
// (CHOLMOD) while the tangent is positive definite, as it is at stable equilibria, and
// a general LU (UMFPACK) for a factorisation where the Cholesky breaks down (past a
// limit point, under compressive instability). Unsymmetric tangents (follower loads)
// and an explicit solver kind go straight to that one.
class TangentSolver {
 public:
  TangentSolver(linalg::SolverKind kind, bool unsymmetric);
  const linalg::SolveReport& factorize(const linalg::SparseMatrix& k);
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const;

 private:
  std::unique_ptr<linalg::LinearSolver> spd_, general_;
  const linalg::LinearSolver* active_ = nullptr;
  int skip_cholesky_ = 0;  // after a breakdown, the next few factorisations go to the LU
};

}  // namespace sf::forming
