#include "common/linalg/sparse.hpp"

#include <limits>

#include "common/core/error.hpp"

namespace sf::linalg {

namespace {
constexpr Index kMaxSparseIndex = std::numeric_limits<int>::max();
}  // namespace

TripletAssembler::TripletAssembler(Index n_rows, Index n_cols) : n_rows_(n_rows), n_cols_(n_cols) {
  SF_ASSERT(n_rows >= 0 && n_cols >= 0, "matrix size must be non-negative");
  SF_ASSERT(n_rows <= kMaxSparseIndex && n_cols <= kMaxSparseIndex,
            "matrix size does not fit the int indices of SparseMatrix");
}

void TripletAssembler::reserve(Index n) {
  if (n > 0) triplets_.reserve(static_cast<std::size_t>(n));
}

void TripletAssembler::add(Index i, Index j, double v) {
  if (i < 0 || j < 0) return;
  SF_ASSERT(i < n_rows_, "row index out of range");
  SF_ASSERT(j < n_cols_, "column index out of range");
  triplets_.emplace_back(static_cast<int>(i), static_cast<int>(j), v);
}

void TripletAssembler::add_block(const std::vector<Index>& rows, const std::vector<Index>& cols,
                                 const Eigen::Ref<const Eigen::MatrixXd>& block) {
  SF_ASSERT(block.rows() == static_cast<Eigen::Index>(rows.size()),
            "block has a different number of rows than the row index list");
  SF_ASSERT(block.cols() == static_cast<Eigen::Index>(cols.size()),
            "block has a different number of columns than the column index list");
  // Column-major traversal matches the block's storage.
  for (std::size_t b = 0; b < cols.size(); ++b) {
    const Index j = cols[b];
    if (j < 0) continue;
    SF_ASSERT(j < n_cols_, "column index out of range");
    for (std::size_t a = 0; a < rows.size(); ++a) {
      const Index i = rows[a];
      if (i < 0) continue;
      SF_ASSERT(i < n_rows_, "row index out of range");
      triplets_.emplace_back(static_cast<int>(i), static_cast<int>(j),
                             block(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)));
    }
  }
}

SparseMatrix TripletAssembler::compress() const {
  SparseMatrix m(n_rows_, n_cols_);
  m.setFromTriplets(triplets_.begin(), triplets_.end());  // sums duplicates
  m.makeCompressed();
  return m;
}

std::vector<Index> empty_rows(const SparseMatrix& a) {
  std::vector<char> has_value(static_cast<std::size_t>(a.rows()), 0);
  for (int k = 0; k < a.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(a, k); it; ++it) {
      if (it.value() != 0.0) has_value[static_cast<std::size_t>(it.row())] = 1;
    }
  }
  std::vector<Index> out;
  for (std::size_t r = 0; r < has_value.size(); ++r) {
    if (!has_value[r]) out.push_back(static_cast<Index>(r));
  }
  return out;
}

}  // namespace sf::linalg
