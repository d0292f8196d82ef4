#include "forming/solve/tangent_solver.hpp"

#include <atomic>
#include <chrono>

#include "common/core/error.hpp"
#include "forming/model/model.hpp"
#include "forming/model/solve_profile.hpp"

namespace sf::forming {

namespace {
std::atomic<int> g_default_ordering{static_cast<int>(linalg::Ordering::kDefault)};
}  // namespace

void TangentSolver::set_default_ordering(linalg::Ordering ordering) {
  g_default_ordering.store(static_cast<int>(ordering));
}

linalg::Ordering TangentSolver::default_ordering() { return static_cast<linalg::Ordering>(g_default_ordering.load()); }

TangentSolver::TangentSolver(linalg::SolverKind kind, bool unsymmetric) {
  using linalg::SolverKind;
  const linalg::Ordering ordering = default_ordering();
  const bool symmetric_auto = kind == SolverKind::kAuto && !unsymmetric;
  if (symmetric_auto && linalg::solver_available(SolverKind::kCholmod)) {
    spd_ = std::make_unique<linalg::LinearSolver>(SolverKind::kCholmod,
                                                  linalg::MatrixProperty::kSymmetricPositiveDefinite);
    // The indefinite fallback: UMFPACK (symmetric strategy, threshold pivoting) on the
    // matrix expanded from its lower triangle. CHOLMOD's LDL^T is simplicial (no BLAS):
    // on the dome's start tangent 2x slower than UMFPACK at 1944 unknowns and 9x (6.5
    // against 0.72 processor seconds) at 10584 (bench/simform_dome_bench --factor-only).
    const SolverKind fallback =
        linalg::solver_available(SolverKind::kUmfpack) ? SolverKind::kUmfpack : SolverKind::kCholmodLdlt;
    general_ = std::make_unique<linalg::LinearSolver>(fallback, linalg::MatrixProperty::kSymmetricIndefinite);
    spd_->set_ordering(ordering);
    general_->set_ordering(ordering);
    lower_ = true;
    return;
  }
  if (symmetric_auto) kind = SolverKind::kEigenLDLT;  // no SuiteSparse
  general_ = std::make_unique<linalg::LinearSolver>(
      kind, unsymmetric ? linalg::MatrixProperty::kUnsymmetric : linalg::MatrixProperty::kSymmetricIndefinite);
  general_->set_ordering(ordering);
  lower_ = !unsymmetric && linalg::reads_lower_triangle(general_->kind());
}

const linalg::SolveReport& TangentSolver::factorize(const linalg::SparseMatrix& k) {
  const auto t0 = std::chrono::steady_clock::now();
  SolveProfile& profile = solve_profile();
  ++profile.factorizations;
  struct AddTime {
    std::chrono::steady_clock::time_point t0;
    double& to;
    ~AddTime() { to += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
  } timer{t0, profile.factorize_s};
  const auto record = [&profile](const linalg::SolveReport& r) {
    if (!r.reused_analysis) {
      ++profile.analyses;
      profile.analyse_s += r.analyze_seconds;
    }
    profile.n = static_cast<long>(r.n_rows);
    profile.nnz = static_cast<long>(r.n_nonzeros);
    profile.factor_nnz = r.factor_nonzeros;
    profile.factor_flops = r.factor_flops;
    profile.solver = linalg::to_string(r.used);
    profile.ordering = r.ordering;
  };
  if (!ordering_chosen_) {
    // UMFPACK's default AMD against METIS on the dome's start tangent (bench/
    // simform_dome_bench --factor-only): at 1944 unknowns AMD needs fewer flops (0.33
    // against 0.46 Gflop), at 10584 METIS (14.8 against 20.2 Gflop, 25 % less time), at
    // 40344 (20 x 20 bricks, 4 plies) see docs. CHOLMOD's default already tries both.
    ordering_chosen_ = true;
    if (default_ordering() == linalg::Ordering::kDefault && general_->kind() == linalg::SolverKind::kUmfpack &&
        k.rows() >= kMetisFrom)
      general_->set_ordering(linalg::Ordering::kMetis);
  }
  if (spd_ && skip_cholesky_ > 0) {
    --skip_cholesky_;
  } else if (spd_) {
    const linalg::SolveReport& r = spd_->factorize(k);
    record(r);
    if (r.ok()) {
      active_ = spd_.get();
      return r;
    }
    skip_cholesky_ = 4;
  }
  if (spd_) ++n_indefinite_;
  if (lower_ && !linalg::reads_lower_triangle(general_->kind())) {
    // Both triangles for the LU; the same lower pattern expands to the same full one, so
    // its analysis is kept as well.
    expanded_ = k.selfadjointView<Eigen::Lower>();
    const linalg::SolveReport& r = general_->factorize(expanded_);
    record(r);
    active_ = r.ok() ? general_.get() : nullptr;
    return r;
  }
  const linalg::SolveReport& r = general_->factorize(k);
  record(r);
  active_ = r.ok() ? general_.get() : nullptr;
  return r;
}

Eigen::MatrixXd TangentSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const {
  SF_ASSERT(active_ != nullptr, "TangentSolver::solve() needs a successful factorize()");
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd x = active_->solve(b);
  SolveProfile& profile = solve_profile();
  ++profile.solves;
  profile.solve_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return x;
}

FreeDofs::FreeDofs(const std::vector<bool>& free) : is_free(free) {
  const Index n = static_cast<Index>(free.size());
  for (Index d = 0; d < n; ++d)
    if (free[static_cast<std::size_t>(d)]) index.push_back(d);
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

VecX FreeDofs::expand(const VecX& v_free) const {
  VecX out = VecX::Zero(static_cast<Index>(is_free.size()));
  for (Index j = 0; j < size(); ++j) out(index[j]) = v_free(j);
  return out;
}

void TangentWorkspace::prepare(const Model& model, const std::vector<bool>& is_free, linalg::SolverKind kind,
                               bool unsymmetric) {
  const bool same = solver_ && pattern_ && model_ == &model && n_dofs_ == model.n_dofs() &&
                    n_elements_ == model.element_entries().size() && kind_ == kind && unsymmetric_ == unsymmetric &&
                    is_free_ == is_free;
  if (same) return;
  model_ = &model;
  n_dofs_ = model.n_dofs();
  n_elements_ = model.element_entries().size();
  is_free_ = is_free;
  kind_ = kind;
  unsymmetric_ = unsymmetric;
  solver_ = std::make_unique<TangentSolver>(kind, unsymmetric);
  lay_out(model);
}

void TangentWorkspace::make_unsymmetric(const Model& model) {
  solver_ = std::make_unique<TangentSolver>(kind_, true);
  unsymmetric_ = true;
  lay_out(model);
}

void TangentWorkspace::lay_out(const Model& model) {
  const auto t0 = std::chrono::steady_clock::now();
  pattern_.reset();  // release the old tables before building the new ones
  pattern_ = std::make_unique<linalg::PatternAssembler>(model.make_pattern(is_free_, solver_->lower()));
  layout_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++layouts_;
}

}  // namespace sf::forming
