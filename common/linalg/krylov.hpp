#pragma once
// Restarted GMRES (right-preconditioned) for a square sparse A x = b, and the
// block-diagonal part of A as its preconditioner.
//
// GMRES(m) (Saad and Schultz 1986) with modified Gram-Schmidt and Givens rotations,
// preconditioned on the right: it minimises the true residual |b - A x| over the Krylov
// space of A M^-1, so the residual it reports is that of A x = b (checked against an
// explicit product at the end and at every restart). Convergence when
// |b - A x| <= tolerance |b|.
//
// Block-diagonal preconditioner (block_diagonal()): the unknowns are split into groups (e.g. the plies of a
// laminate: unknown i belongs to group[i]); M keeps the entries of A whose row and column
// are in the same group and drops the coupling between groups (contact between plies),
// which the Krylov iteration then handles. M is block diagonal, so its direct
// factorisation (LinearSolver: the fill-reducing ordering separates the blocks) costs the
// blocks' factorisations only, far less than A's. Its pattern stays while A's does, so
// the symbolic analysis is kept; the caller may keep one factorisation of M over several
// solves with changing A (forming/solve/tangent_solver.hpp refactors when GMRES needs
// many more iterations than just after a factorisation).
//
// Storage: A is either both triangles (kFull) or, for a symmetric A, its lower triangle
// (kLower; products then use A's self-adjoint view). M is stored the same way.
//
// Typical use (Newton):
//   LinearSolver direct(...); direct.factorize(block_diagonal(k, group));   // when stale
//   Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
//   GmresReport r = gmres(k, storage, [&](auto& v, auto& y) { y = direct.solve(v); }, b, x, {});

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/pattern_assembler.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::linalg {

struct GmresOptions {
  double tolerance = 1e-10;  // relative residual |b - A x| / |b| to reach
  int restart = 80;          // Krylov vectors kept before a restart (memory: restart x n doubles)
  int max_iterations = 400;  // matrix-vector products in all, over the restarts
};

struct GmresReport {
  bool converged = false;
  int iterations = 0;              // matrix-vector products with A (and preconditioner solves)
  double relative_residual = 0.0;  // |b - A x| / |b|, computed explicitly at the end
  double seconds = 0.0;
  std::string brief() const;  // e.g. "gmres: converged in 23 iterations, |r|/|b| 4.1e-11, 0.21 s"
};

// Applies M^-1: y = M^-1 v (n).
using PreconditionerApply = std::function<void(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y)>;

// y = A v for A stored as `storage` (kLower: the lower triangle of a symmetric A).
void multiply(const SparseMatrix& a, Storage storage, const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y);

// Solves A x = b from the initial guess x (n; zero it for none). A is n x n.
GmresReport gmres(const SparseMatrix& a, Storage storage, const PreconditionerApply& precondition,
                  const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::VectorXd& x, const GmresOptions& options);

// The block-diagonal part of A: entries (i, j) with group[i] == group[j] (same storage).
SparseMatrix block_diagonal(const SparseMatrix& a, const std::vector<int>& group);

}  // namespace sf::linalg
