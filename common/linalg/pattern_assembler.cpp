#include "common/linalg/pattern_assembler.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

#include "common/core/error.hpp"

namespace sf::linalg {

std::vector<std::vector<Index>> colour_elements(Index n_dofs, const std::vector<ElementEntries>& elements) {
  std::vector<std::vector<Index>> colours;
  std::vector<std::uint64_t> used(static_cast<std::size_t>(n_dofs), 0);
  std::vector<Index> own;  // elements past 64 colours: one colour each
  for (std::size_t e = 0; e < elements.size(); ++e) {
    std::uint64_t taken = 0;
    for (Index d : elements[e].dofs)
      if (d >= 0) taken |= used[static_cast<std::size_t>(d)];
    if (taken == ~std::uint64_t{0}) {
      own.push_back(static_cast<Index>(e));
      continue;
    }
    const int c = __builtin_ctzll(~taken);
    for (Index d : elements[e].dofs)
      if (d >= 0) used[static_cast<std::size_t>(d)] |= std::uint64_t{1} << c;
    if (static_cast<int>(colours.size()) <= c) colours.resize(static_cast<std::size_t>(c) + 1);
    colours[static_cast<std::size_t>(c)].push_back(static_cast<Index>(e));
  }
  for (Index e : own) colours.push_back({e});
  return colours;
}

PatternAssembler::PatternAssembler(Index n_dofs, const std::vector<bool>& active,
                                   const std::vector<ElementEntries>& elements, Storage storage)
    : n_dofs_(n_dofs), storage_(storage) {
  SF_ASSERT(static_cast<Index>(active.size()) == n_dofs, "one active flag per dof");
  index_.assign(static_cast<std::size_t>(n_dofs), -1);
  for (Index d = 0; d < n_dofs; ++d)
    if (active[static_cast<std::size_t>(d)]) {
      index_[static_cast<std::size_t>(d)] = static_cast<Index>(active_dofs_.size());
      active_dofs_.push_back(d);
    }
  SF_ASSERT(n_active() <= std::numeric_limits<int>::max(), "too many unknowns for int indices");
  place_ = index_;  // natural order: matrix row = unknown

  elements_.resize(elements.size());
  std::vector<int> order;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const ElementEntries& in = elements[e];
    Element& el = elements_[e];
    order.clear();
    for (std::size_t a = 0; a < in.dofs.size(); ++a)
      if (in.dofs[a] >= 0 && index_[static_cast<std::size_t>(in.dofs[a])] >= 0) order.push_back(static_cast<int>(a));
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return in.dofs[a] < in.dofs[b]; });
    for (int a : order) {
      const Index u = index_[static_cast<std::size_t>(in.dofs[a])];
      if (el.unknowns.empty() || el.unknowns.back() != u) {
        el.unknowns.push_back(u);
        el.first_of_slot.push_back(static_cast<int>(el.slot.size()));
      }
      el.slot.push_back(static_cast<int>(el.unknowns.size()) - 1);
      el.local.push_back(in.local[a]);
      el.coef.push_back(in.coefs[a]);
    }
    el.first_of_slot.push_back(static_cast<int>(el.slot.size()));
  }

  // Colouring over ALL dofs an element writes (its force entries too).
  colours_ = colour_elements(n_dofs, elements);
  build_pattern({});
  build_tables();
}

void PatternAssembler::build_pattern(const std::vector<std::pair<Index, Index>>& extra) {
  const Index n = n_active();
  const bool lower = storage_ == Storage::kLower;
  // Elements of each unknown.
  std::vector<Index> start(static_cast<std::size_t>(n) + 1, 0);
  for (const Element& el : elements_)
    for (Index u : el.unknowns) ++start[static_cast<std::size_t>(u) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<Index> fill(start.begin(), start.end() - 1), of(static_cast<std::size_t>(start.back()));
  for (std::size_t e = 0; e < elements_.size(); ++e)
    for (Index u : elements_[e].unknowns) of[static_cast<std::size_t>(fill[static_cast<std::size_t>(u)]++)] = e;
  // Extra entries per column.
  std::vector<std::pair<Index, Index>> ex = extra;  // (column, row)
  for (auto& p : ex) std::swap(p.first, p.second);
  std::sort(ex.begin(), ex.end());

  std::vector<int> outer(static_cast<std::size_t>(n) + 1, 0);
  std::vector<int> inner;
  inner.reserve(elements_.empty() ? 0 : elements_.size() * elements_[0].unknowns.size() * 16);
  std::vector<Index> stamp(static_cast<std::size_t>(n), -1);
  std::vector<int> rows;
  std::size_t next_extra = 0;
  for (Index c = 0; c < n; ++c) {
    rows.clear();
    auto take = [&](Index r) {
      if ((lower && r < c) || stamp[static_cast<std::size_t>(r)] == c) return;
      stamp[static_cast<std::size_t>(r)] = c;
      rows.push_back(static_cast<int>(r));
    };
    for (Index t = start[static_cast<std::size_t>(c)]; t < start[static_cast<std::size_t>(c) + 1]; ++t)
      for (Index r : elements_[static_cast<std::size_t>(of[static_cast<std::size_t>(t)])].unknowns) take(r);
    for (; next_extra < ex.size() && ex[next_extra].first == c; ++next_extra) take(ex[next_extra].second);
    std::sort(rows.begin(), rows.end());
    inner.insert(inner.end(), rows.begin(), rows.end());
    outer[static_cast<std::size_t>(c) + 1] = static_cast<int>(inner.size());
  }
  matrix_ = SparseMatrix(n, n);
  matrix_.resizeNonZeros(static_cast<Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), matrix_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), matrix_.innerIndexPtr());
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + inner.size(), 0.0);
}

void PatternAssembler::build_tables() {
  const bool lower = storage_ == Storage::kLower;
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  for (Element& el : elements_) {
    const int u = static_cast<int>(el.unknowns.size());
    el.pos.assign(lower ? static_cast<std::size_t>(u) * (u + 1) / 2 : static_cast<std::size_t>(u) * u, -1);
    std::size_t out = 0;
    for (int c = 0; c < u; ++c) {
      const Index col = el.unknowns[static_cast<std::size_t>(c)];
      int p = outer[col];
      const int end = outer[col + 1];
      for (int r = lower ? c : 0; r < u; ++r, ++out) {
        const int row = static_cast<int>(el.unknowns[static_cast<std::size_t>(r)]);
        while (p < end && inner[p] < row) ++p;
        SF_ASSERT(p < end && inner[p] == row, "element entry missing from the pattern");
        el.pos[out] = p;
      }
    }
  }
}

void PatternAssembler::set_zero() { std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0); }

void PatternAssembler::add_element(Index e, const double* k, int ld) {
  const Element& el = elements_[static_cast<std::size_t>(e)];
  const int n = static_cast<int>(el.slot.size());
  const long u = static_cast<long>(el.unknowns.size());
  double* val = matrix_.valuePtr();
  const int* pos = el.pos.data();
  const int* slot = el.slot.data();
  const int* local = el.local.data();
  const double* coef = el.coef.data();
  if (storage_ == Storage::kLower) {
    for (int b = 0; b < n; ++b) {
      const long sc = slot[b];
      const double* kc = k + static_cast<long>(local[b]) * ld;
      const double cb = coef[b];
      // Packed column sc starts at sc u - sc (sc - 1) / 2 and holds slots sc .. u - 1.
      const int* pc = pos + (sc * u - sc * (sc - 1) / 2 - sc);
      for (int a = el.first_of_slot[static_cast<std::size_t>(sc)]; a < n; ++a)
        val[pc[slot[a]]] += coef[a] * cb * kc[local[a]];
    }
  } else {
    for (int b = 0; b < n; ++b) {
      const int* pc = pos + slot[b] * u;
      const double* kc = k + static_cast<long>(local[b]) * ld;
      const double cb = coef[b];
      for (int a = 0; a < n; ++a) val[pc[slot[a]]] += coef[a] * cb * kc[local[a]];
    }
  }
}

std::int64_t PatternAssembler::find(Index row, Index col) const {
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  const int* begin = inner + outer[col];
  const int* end = inner + outer[col + 1];
  const int* it = std::lower_bound(begin, end, static_cast<int>(row));
  return it != end && *it == row ? static_cast<std::int64_t>(it - inner) : -1;
}

void PatternAssembler::add(Index i, Index j, double v) {
  SF_ASSERT(i >= 0 && i < n_dofs_ && j >= 0 && j < n_dofs_, "dof out of range");
  const Index r = place_[static_cast<std::size_t>(i)], c = place_[static_cast<std::size_t>(j)];
  if (r < 0 || c < 0 || (storage_ == Storage::kLower && r < c)) return;
  const std::int64_t p = find(r, c);
  if (p >= 0)
    matrix_.valuePtr()[p] += v;
  else
    pending_.push_back({{r, c}, v});
}

void PatternAssembler::add(const SparseMatrix& m, double scale) {
  SF_ASSERT(m.rows() == n_dofs_ && m.cols() == n_dofs_, "matrix must be n_dofs x n_dofs");
  for (int k = 0; k < m.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(m, k); it; ++it) add(it.row(), it.col(), scale * it.value());
}

void PatternAssembler::add_block(const std::vector<Index>& rows, const std::vector<Index>& cols, const double* block,
                                 long ld) {
  const std::size_t nr = rows.size();
  thread_local std::vector<int> order, unknown;
  thread_local std::vector<std::int64_t> pos;
  unknown.resize(nr);
  pos.resize(nr);
  order.clear();
  for (std::size_t a = 0; a < nr; ++a) {
    const Index i = rows[a];
    SF_ASSERT(i < n_dofs_, "dof out of range");
    unknown[a] = i >= 0 ? static_cast<int>(place_[static_cast<std::size_t>(i)]) : -1;
    if (unknown[a] >= 0) order.push_back(static_cast<int>(a));
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return unknown[a] < unknown[b]; });
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  double* val = matrix_.valuePtr();
  const bool lower = storage_ == Storage::kLower;
  for (std::size_t b = 0; b < cols.size(); ++b) {
    const Index j = cols[b];
    if (j < 0) continue;
    SF_ASSERT(j < n_dofs_, "dof out of range");
    const Index c = place_[static_cast<std::size_t>(j)];
    if (c < 0) continue;
    // Positions of the rows in column c: -1 dropped, -2 outside the pattern.
    int p = outer[c];
    const int end = outer[c + 1];
    for (std::size_t a = 0; a < nr; ++a) pos[a] = -1;
    for (int a : order) {
      const int r = unknown[static_cast<std::size_t>(a)];
      if (lower && r < c) continue;
      while (p < end && inner[p] < r) ++p;
      pos[static_cast<std::size_t>(a)] = p < end && inner[p] == r ? p : -2;
    }
    const double* col = block + static_cast<long>(b) * ld;
    for (std::size_t a = 0; a < nr; ++a) {
      if (pos[a] >= 0)
        val[pos[a]] += col[a];
      else if (pos[a] == -2)
        pending_.push_back({{unknown[a], c}, col[a]});
    }
  }
}

std::vector<std::int64_t> PatternAssembler::positions_of(const SparseMatrix& m) const {
  SF_ASSERT(m.isCompressed(), "positions_of needs a compressed matrix");
  std::vector<std::int64_t> out(static_cast<std::size_t>(m.nonZeros()), -1);
  std::size_t t = 0;
  for (int k = 0; k < m.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(m, k); it; ++it, ++t) {
      const Index r = place_[static_cast<std::size_t>(it.row())], c = place_[static_cast<std::size_t>(it.col())];
      if (r < 0 || c < 0 || (storage_ == Storage::kLower && r < c)) continue;
      out[t] = find(r, c);
    }
  return out;
}

bool PatternAssembler::flush() {
  if (pending_.empty()) return false;
  const SparseMatrix old = matrix_;
  for (const auto& [rc, v] : pending_) extra_.push_back(rc);
  std::sort(extra_.begin(), extra_.end());
  extra_.erase(std::unique(extra_.begin(), extra_.end()), extra_.end());
  build_pattern(extra_);
  // Old values to their new places (the new rows of a column are a superset).
  for (int c = 0; c < old.outerSize(); ++c) {
    int p = matrix_.outerIndexPtr()[c];
    for (int q = old.outerIndexPtr()[c]; q < old.outerIndexPtr()[c + 1]; ++q) {
      while (matrix_.innerIndexPtr()[p] < old.innerIndexPtr()[q]) ++p;
      matrix_.valuePtr()[p] = old.valuePtr()[q];
    }
  }
  build_tables();
  ++generation_;
  std::vector<std::pair<std::pair<Index, Index>, double>> pending;
  pending.swap(pending_);
  for (const auto& [rc, v] : pending) matrix_.valuePtr()[find(rc.first, rc.second)] += v;
  return true;
}

void PatternAssembler::set_order(const std::vector<int>& order) {
  SF_ASSERT(pending_.empty(), "set_order: flush() the entries kept aside first");
  const Index n = n_active();
  const std::size_t un = static_cast<std::size_t>(n);
  // New row of each unknown.
  std::vector<Index> row_of(un);
  if (order.empty()) {
    std::iota(row_of.begin(), row_of.end(), Index{0});
  } else {
    SF_ASSERT(static_cast<Index>(order.size()) == n, "set_order: one entry per unknown");
    std::fill(row_of.begin(), row_of.end(), Index{-1});
    for (std::size_t k = 0; k < un; ++k) {
      const int u = order[k];
      SF_ASSERT(u >= 0 && u < n && row_of[static_cast<std::size_t>(u)] < 0, "set_order: not a permutation");
      row_of[static_cast<std::size_t>(u)] = static_cast<Index>(k);
    }
  }
  // Old matrix row -> new one.
  std::vector<Index> moved(un);
  for (std::size_t r = 0; r < un; ++r)
    moved[r] = row_of[order_.empty() ? r : static_cast<std::size_t>(order_[r])];
  const bool lower = storage_ == Storage::kLower;
  auto to_new = [&](Index r, Index c) {
    Index a = moved[static_cast<std::size_t>(r)], b = moved[static_cast<std::size_t>(c)];
    if (lower && a < b) std::swap(a, b);
    return std::make_pair(a, b);
  };

  // Each element's entries sorted by their new rows; ties (a dof repeated in an element)
  // keep their order, as the constructor would have made them.
  std::vector<int> idx;
  std::vector<Index> key;
  for (Element& el : elements_) {
    const std::size_t m = el.slot.size();
    key.resize(m);
    idx.resize(m);
    for (std::size_t a = 0; a < m; ++a) {
      key[a] = moved[static_cast<std::size_t>(el.unknowns[static_cast<std::size_t>(el.slot[a])])];
      idx[a] = static_cast<int>(a);
    }
    std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return key[a] < key[b]; });
    Element out;
    out.slot.reserve(m);
    out.local.reserve(m);
    out.coef.reserve(m);
    out.unknowns.reserve(el.unknowns.size());
    out.first_of_slot.reserve(el.first_of_slot.size());
    for (int a : idx) {
      if (out.unknowns.empty() || out.unknowns.back() != key[a]) {
        out.unknowns.push_back(key[a]);
        out.first_of_slot.push_back(static_cast<int>(out.slot.size()));
      }
      out.slot.push_back(static_cast<int>(out.unknowns.size()) - 1);
      out.local.push_back(el.local[static_cast<std::size_t>(a)]);
      out.coef.push_back(el.coef[static_cast<std::size_t>(a)]);
    }
    out.first_of_slot.push_back(static_cast<int>(out.slot.size()));
    el = std::move(out);
  }
  for (auto& rc : extra_) rc = to_new(rc.first, rc.second);
  std::sort(extra_.begin(), extra_.end());
  for (Index d = 0; d < n_dofs_; ++d) {
    const Index u = index_[static_cast<std::size_t>(d)];
    place_[static_cast<std::size_t>(d)] = u < 0 ? -1 : row_of[static_cast<std::size_t>(u)];
  }
  order_ = order;
  bool natural = true;
  for (std::size_t k = 0; k < order_.size() && natural; ++k) natural = order_[k] == static_cast<int>(k);
  if (natural) order_.clear();

  // The new layout, the values carried over (none to carry when all are zero: a pattern
  // not assembled yet).
  const SparseMatrix old = std::move(matrix_);
  build_pattern(extra_);
  const bool zero = std::all_of(old.valuePtr(), old.valuePtr() + old.nonZeros(), [](double v) { return v == 0.0; });
  for (int c = 0; c < (zero ? 0 : static_cast<int>(old.outerSize())); ++c)
    for (int q = old.outerIndexPtr()[c]; q < old.outerIndexPtr()[c + 1]; ++q) {
      const auto [r_new, c_new] = to_new(old.innerIndexPtr()[q], c);
      const std::int64_t p = find(r_new, c_new);
      SF_ASSERT(p >= 0, "set_order: an entry lost in the new layout");
      matrix_.valuePtr()[p] = old.valuePtr()[q];
    }
  build_tables();
  ++generation_;
}

std::size_t PatternAssembler::memory_bytes() const {
  std::size_t bytes = static_cast<std::size_t>(matrix_.nonZeros()) * (sizeof(double) + sizeof(int)) +
                      static_cast<std::size_t>(matrix_.outerSize() + 1) * sizeof(int) +
                      (index_.size() + place_.size()) * sizeof(Index) + order_.size() * sizeof(int) +
                      active_dofs_.size() * sizeof(Index);
  for (const Element& el : elements_)
    bytes += el.pos.size() * sizeof(int) + el.slot.size() * (2 * sizeof(int) + sizeof(double)) +
             el.unknowns.size() * sizeof(Index) + el.first_of_slot.size() * sizeof(int);
  return bytes;
}

}  // namespace sf::linalg
