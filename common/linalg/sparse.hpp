#pragma once
// Sparse matrix type and triplet assembly for finite-element systems.
//
// Conventions
//  - SparseMatrix is column-major with 32-bit (int) indices: the layout CHOLMOD,
//    UMFPACK and Eigen's sparse solvers take without copying. Sizes and indices
//    in the API are sf::Index (64-bit) and are checked to fit in an int.
//  - DOF numbering is the caller's; a negative DOF index means "constrained or
//    unused" and every contribution to such a row or column is skipped.
//  - Duplicated (i, j) entries are summed on compress(). Explicit zeros are kept,
//    so the sparsity pattern depends only on which (i, j) were added, not on the
//    values: re-assembling the same mesh gives the same pattern, which lets
//    LinearSolver reuse its symbolic analysis.
//
// Typical use (element loop):
//   TripletAssembler assembler(n_dofs, n_dofs);
//   assembler.reserve(n_elements * n_e * n_e);
//   for (each element) assembler.add_block(dofs, dofs, k_e);  // k_e: n_e x n_e
//   SparseMatrix k = assembler.compress();

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "common/core/types.hpp"

namespace sf::linalg {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Collects (row, col, value) triplets and builds a compressed SparseMatrix.
// Not thread-safe: use one assembler per thread and add the matrices, or
// assemble serially.
class TripletAssembler {
 public:
  // An n_rows x n_cols matrix; both must be >= 0 and fit in an int.
  TripletAssembler(Index n_rows, Index n_cols);

  Index n_rows() const { return n_rows_; }
  Index n_cols() const { return n_cols_; }
  // Number of triplets stored so far (duplicates counted separately).
  Index n_triplets() const { return static_cast<Index>(triplets_.size()); }

  // Reserves room for n triplets in total (not in addition to those stored).
  void reserve(Index n);

  // Adds v to entry (i, j). If i < 0 or j < 0 nothing is added.
  // Requires i < n_rows(), j < n_cols() (debug-checked).
  void add(Index i, Index j, double v);

  // Adds block(a, b) to entry (rows[a], cols[b]) for every a, b, skipping
  // negative rows[a] or cols[b]. block is rows.size() x cols.size() (debug-checked).
  void add_block(const std::vector<Index>& rows, const std::vector<Index>& cols,
                 const Eigen::Ref<const Eigen::MatrixXd>& block);

  // Builds the compressed n_rows x n_cols matrix with duplicates summed. The
  // triplets are kept, so compress() may be called again after more add()s.
  SparseMatrix compress() const;

  // Drops all triplets (keeps the capacity and the size).
  void clear() { triplets_.clear(); }

  // The triplets added so far (duplicates not summed), in the order they were added.
  const std::vector<Eigen::Triplet<double, int>>& triplets() const { return triplets_; }

 private:
  Index n_rows_;
  Index n_cols_;
  std::vector<Eigen::Triplet<double, int>> triplets_;
};

// Rows of a that hold no nonzero value (no stored entry, or only stored zeros),
// in ascending order. A stiffness matrix row like that belongs to a DOF no
// element touches; callers pin it (unit diagonal, zero right-hand side) before
// factorising.
std::vector<Index> empty_rows(const SparseMatrix& a);

}  // namespace sf::linalg
