#pragma once
// Element-by-element assembly into a sparsity pattern that is built once: the matrix of
// the ACTIVE unknowns (e.g. the free dofs of a Newton solve) is laid out when the
// assembler is made, each element gets a table of the positions its entries go to, and
// every later assembly writes values in place (no triplets, no sorting, no selection
// product). Entries from elsewhere (contact pairs that change between iterations) are
// merged into the pattern; the pattern grows only when one falls outside it.
//
// Numbering
//   Global dofs 0 .. n_dofs - 1 (the caller's). active[d] makes dof d an unknown: the
//   matrix is n_active x n_active, unknown j = the j-th active dof in increasing order
//   (active_index(d)); rows and columns of inactive dofs are dropped. The matrix's rows
//   and columns are the unknowns in that order unless set_order() gave another one.
//
// Elements
//   Element e lists its entries a = 0 .. m_e - 1: global dof dofs[a] (or -1: none),
//   coefficient coefs[a] and local index local[a] into the element matrix; entry (a, b)
//   of the assembled matrix receives coefs[a] coefs[b] k(local[a], local[b]). Repeated
//   dofs within an element are summed (collapsed elements).
//
// Storage
//   kLower: the lower triangle only (row >= column), for symmetric matrices (what
//   CHOLMOD and MUMPS read); kFull: both triangles (unsymmetric solvers). The matrix is
//   a compressed column-major linalg::SparseMatrix whose rows are sorted in each column.
//
// Threads
//   colours(): the elements in groups of which no two share an active dof (greedy
//   colouring, in element order). Elements of one colour may be added concurrently;
//   adding colour after colour gives every entry its contributions in the same order
//   whatever the number of threads, so the sums are identical bit for bit.
//
// Typical use (Newton):
//   PatternAssembler pa(n_dofs, is_free, element_entries, Storage::kLower);
//   per iteration: pa.set_zero(); for colour: (parallel) for e: pa.add_element(e, k_e);
//                  pa.add(i, j, v) for extra entries;  factorise pa.matrix()

#include <cstdint>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::linalg {

enum class Storage { kLower, kFull };

struct ElementEntries {
  std::vector<Index> dofs;    // global dof per entry (-1: none)
  std::vector<double> coefs;  // its coefficient
  std::vector<int> local;     // its row/column in the element matrix
};

// Greedy colouring of elements by every dof >= 0 they list: no two elements of a colour
// share a dof. Colour c holds its elements in increasing order.
std::vector<std::vector<Index>> colour_elements(Index n_dofs, const std::vector<ElementEntries>& elements);

class PatternAssembler {
 public:
  PatternAssembler(Index n_dofs, const std::vector<bool>& active, const std::vector<ElementEntries>& elements,
                   Storage storage);

  Index n_dofs() const { return n_dofs_; }
  Index n_active() const { return static_cast<Index>(active_dofs_.size()); }
  Storage storage() const { return storage_; }
  // Active dofs in increasing order, and dof -> unknown (-1 when inactive).
  const std::vector<Index>& active_dofs() const { return active_dofs_; }
  Index active_index(Index dof) const { return index_[static_cast<std::size_t>(dof)]; }
  Index n_elements() const { return static_cast<Index>(elements_.size()); }
  // Elements grouped so that no two in a group share an active dof (see header).
  const std::vector<std::vector<Index>>& colours() const { return colours_; }
  // Incremented whenever the pattern changes (grows); values laid out for an older
  // generation must be laid out again.
  int generation() const { return generation_; }

  // The assembled matrix (n_active x n_active, `storage` triangle(s)).
  const SparseMatrix& matrix() const { return matrix_; }
  SparseMatrix& matrix() { return matrix_; }
  void set_zero();
  // Adds element e's matrix k (column-major, leading dimension ld, indexed by `local`).
  // Safe concurrently for elements of one colour.
  void add_element(Index e, const double* k, int ld);
  // Adds v to the entry of global dofs (i, j): skipped when either is inactive, and for
  // kLower when it lies above the diagonal (its mirror carries it). An entry outside the
  // pattern is kept aside and merged by the next flush(). Not thread-safe.
  void add(Index i, Index j, double v);
  // Adds scale * m (n_dofs x n_dofs, any pattern) entry by entry, as add().
  void add(const SparseMatrix& m, double scale);
  // Adds block(a, b) to the entry of global dofs (rows[a], cols[b]) for every a, b, as
  // add() would, in the same order (column by column, rows in order within a column):
  // negative dofs are skipped like a TripletAssembler skips them, inactive ones and
  // kLower's upper triangle are dropped, entries outside the pattern kept aside for
  // flush(). One walk down each pattern column instead of a search per entry; block is
  // column-major with leading dimension ld. Not thread-safe. (Contact pairs' blocks,
  // whose pairs change between iterations: forming/contact/surface_contact.cpp.)
  void add_block(const std::vector<Index>& rows, const std::vector<Index>& cols, const double* block, long ld);
  // Grows the pattern by the entries add() kept aside (values are kept) and adds them;
  // false when there were none. Call after the last add() of an assembly.
  bool flush();
  // True when add() has kept entries aside since the last flush() (the pattern will grow).
  bool has_pending() const { return !pending_.empty(); }
  // Positions in matrix().valuePtr() of the entries of m (n_dofs x n_dofs) as add()
  // would place them, -1 for dropped entries and for entries outside the pattern.
  std::vector<std::int64_t> positions_of(const SparseMatrix& m) const;

  // Lays the matrix out with its rows and columns in `order`: row (and column) k of
  // matrix() holds unknown order[k], so for kLower matrix() is tril(P A P^T) with A the
  // matrix in the natural order and P the permutation matrix of `order` ((P A P^T)(k, l) =
  // A(order[k], order[l])). A fill-reducing order from a solver's analysis of the natural
  // pattern so makes matrix() the matrix that solver factorises, written in place by the
  // assembly (LinearSolver with Ordering::kNatural: no permuted copy, no value map).
  // Empty: the natural order. Values and extra entries are carried over; the element
  // tables are laid out again, generation() increases. Everything addressed by global
  // dofs (add, positions_of) keeps working; vectors in unknown order are permuted by the
  // caller (x_matrix(k) = x(order[k])). Requires no pending entries (flush() first).
  void set_order(const std::vector<int>& order);
  // The order of the matrix's rows and columns (see set_order); empty: natural.
  const std::vector<int>& order() const { return order_; }

  // Memory held by the pattern, the values and the element tables, bytes.
  std::size_t memory_bytes() const;

 private:
  struct Element {
    // Entries sorted by matrix row (the unknown's row in the order of set_order), inactive
    // ones dropped: slot (rank of its row among the element's distinct rows), coefficient,
    // local index.
    std::vector<int> slot, local;
    std::vector<double> coef;
    std::vector<int> first_of_slot;  // first sorted entry of each slot (+ end)
    std::vector<Index> unknowns;     // distinct matrix rows of its unknowns, increasing
    std::vector<int> pos;            // positions of slot pairs (packed lower columns, or U x U)
  };
  void build_pattern(const std::vector<std::pair<Index, Index>>& extra);
  void build_tables();
  std::int64_t find(Index row, Index col) const;  // -1 when outside

  Index n_dofs_ = 0;
  Storage storage_ = Storage::kLower;
  std::vector<Index> active_dofs_, index_;
  std::vector<Index> place_;  // dof -> row of matrix_ (index_ permuted by order_), -1 when inactive
  std::vector<int> order_;    // row k of matrix_ holds unknown order_[k]; empty: natural
  std::vector<Element> elements_;
  std::vector<std::vector<Index>> colours_;
  std::vector<std::pair<Index, Index>> extra_;                       // merged entries beyond the elements' pattern
  std::vector<std::pair<std::pair<Index, Index>, double>> pending_;  // kept aside by add()
  SparseMatrix matrix_;
  int generation_ = 0;
};

}  // namespace sf::linalg
