#include "forming/solve/tangent_solver.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>

#include "common/core/error.hpp"
#include "common/linalg/krylov.hpp"
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

std::string to_string(LinearMode mode) {
  switch (mode) {
    case LinearMode::kAuto:
      return "auto";
    case LinearMode::kDirect:
      return "direct";
    case LinearMode::kIterative:
      return "iterative";
    case LinearMode::kIterativePly:
      return "iterative-ply";
  }
  return "unknown";
}

LinearMode parse_linear_mode(const std::string& name, const std::string& where) {
  for (LinearMode m : {LinearMode::kAuto, LinearMode::kDirect, LinearMode::kIterative, LinearMode::kIterativePly})
    if (name == to_string(m)) return m;
  throw InputError(fmt::format("{}{}expected direct, iterative, iterative-ply or auto, found '{}'", where,
                               where.empty() ? "" : ": ", name));
}

TangentSolver::TangentSolver(linalg::SolverKind kind, bool unsymmetric, LinearMode mode, std::vector<int> group)
    : mode_(mode), group_(std::move(group)) {
  using linalg::SolverKind;
  if (mode_ == LinearMode::kIterativePly) {
    // Per-ply blocks need several plies; with one the block is the whole matrix.
    bool several = false;
    for (std::size_t i = 1; i < group_.size() && !several; ++i) several = group_[i] != group_[0];
    if (!several) mode_ = LinearMode::kIterative;
  }
  // kAuto: direct at every size measured (the iterative mode was break-even at 1944 and
  // 10584 unknowns and ~15-20 % less processor time at 40344: not enough to switch by size).
  if (mode_ == LinearMode::kAuto) mode_ = LinearMode::kDirect;
  use_iterative_ = mode_ != LinearMode::kDirect;
  fallback_kind_ = kind;
  fallback_unsymmetric_ = unsymmetric;
  const linalg::Ordering ordering = default_ordering();
  const bool symmetric_auto = kind == SolverKind::kAuto && !unsymmetric;
  if (symmetric_auto && linalg::solver_available(SolverKind::kCholmod)) {
    spd_ = std::make_unique<linalg::LinearSolver>(SolverKind::kCholmod,
                                                  linalg::MatrixProperty::kSymmetricPositiveDefinite);
    spd_->set_ordering(ordering);
    spd_ordering_ = ordering;
    // Where Cholesky breaks down: MUMPS's LDL^T with pivoting on the same lower triangle
    // (see the header), checked by the residual of each solution.
    if (linalg::solver_available(SolverKind::kMumpsLdlt)) {
      indefinite_ =
          std::make_unique<linalg::LinearSolver>(SolverKind::kMumpsLdlt, linalg::MatrixProperty::kSymmetricIndefinite);
      indefinite_->set_ordering(ordering);
    }
    // The last resort (and the indefinite solver of builds without MUMPS): UMFPACK
    // (symmetric strategy, threshold pivoting) on the matrix expanded from its lower
    // triangle. CHOLMOD's LDL^T is simplicial (no BLAS, no pivoting): on the dome's start
    // tangent 2x slower than UMFPACK at 1944 unknowns and 9x (6.5 against 0.72 processor
    // seconds) at 10584 (bench/simform_dome_bench --factor-only).
    const SolverKind fallback =
        linalg::solver_available(SolverKind::kUmfpack) ? SolverKind::kUmfpack : SolverKind::kCholmodLdlt;
    general_ = std::make_unique<linalg::LinearSolver>(fallback, linalg::MatrixProperty::kSymmetricIndefinite);
    general_->set_ordering(ordering);
    if (use_iterative_) general_->set_refinement(false);  // a preconditioner: GMRES refines
    lower_ = true;
    return;
  }
  if (kind == SolverKind::kAuto && unsymmetric && linalg::solver_available(SolverKind::kMumps)) {
    // An unsymmetric tangent (viscous inter-ply slip, friction, follower loads): MUMPS's
    // multifrontal LU, 0.72x of UMFPACK's processor time on the dome's tangents (see the
    // header), its solutions checked; UMFPACK (else Eigen's LU) when it fails.
    general_ = std::make_unique<linalg::LinearSolver>(SolverKind::kMumps, linalg::MatrixProperty::kUnsymmetric);
    general_->set_ordering(ordering);
    lu_fallback_ = std::make_unique<linalg::LinearSolver>(SolverKind::kAuto, linalg::MatrixProperty::kUnsymmetric);
    lu_fallback_->set_ordering(ordering);
    if (use_iterative_) lu_fallback_->set_refinement(false);
    lower_ = false;
    return;
  }
  if (symmetric_auto) kind = SolverKind::kEigenLDLT;  // no SuiteSparse
  general_ = std::make_unique<linalg::LinearSolver>(
      kind, unsymmetric ? linalg::MatrixProperty::kUnsymmetric : linalg::MatrixProperty::kSymmetricIndefinite);
  general_->set_ordering(ordering);
  lower_ = !unsymmetric && linalg::reads_lower_triangle(general_->kind());
  if (use_iterative_) general_->set_refinement(false);  // a preconditioner: GMRES refines
}

bool TangentSolver::lay_out(linalg::PatternAssembler& pattern) {
  pattern_ = nullptr;
  order_.clear();
  if (!spd_ || use_iterative_ || pattern.storage() != linalg::Storage::kLower || pattern.has_pending()) {
    if (!pattern.order().empty() && !pattern.has_pending()) pattern.set_order({});
    return false;
  }
  pattern_ = &pattern;
  reorder();
  return true;
}

void TangentSolver::reorder() {
  linalg::PatternAssembler& p = *pattern_;
  // The ordering from the natural pattern, as factorize() of the natural matrix would
  // choose it (so the factor, and every result, is the same), then the pattern in it.
  if (!p.order().empty()) p.set_order({});
  spd_->keep_copy(false);
  spd_->set_ordering(spd_ordering_);
  const linalg::SolveReport& r = spd_->analyze_pattern(p.matrix());
  std::vector<int> perm = r.status == linalg::SolveReport::Status::kNotFactorized ? spd_->permutation()
                                                                                  : std::vector<int>();
  order_name_ = r.ordering;
  spd_->set_ordering(linalg::Ordering::kNatural);  // drops that analysis (and its map)
  if (!perm.empty()) p.set_order(perm);
  order_ = p.order();
  pattern_generation_ = p.generation();
}

const linalg::SparseMatrix& TangentSolver::natural(const linalg::SparseMatrix& k) {
  if (order_.empty()) return k;
  // tril(P^T B P) of the lower triangle B (row r of B is unknown order_[r]).
  const int n = static_cast<int>(k.rows());
  std::vector<int> count(static_cast<std::size_t>(n) + 1, 0);
  const int* col = k.outerIndexPtr();
  const int* row = k.innerIndexPtr();
  const double* val = k.valuePtr();
  auto unknown = [&](int r) { return order_[static_cast<std::size_t>(r)]; };
  for (int c = 0; c < n; ++c)
    for (int q = col[c]; q < col[c + 1]; ++q) ++count[static_cast<std::size_t>(std::min(unknown(row[q]), unknown(c))) + 1];
  for (int c = 0; c < n; ++c) count[static_cast<std::size_t>(c) + 1] += count[static_cast<std::size_t>(c)];
  natural_.resize(n, n);
  natural_.resizeNonZeros(k.nonZeros());
  std::copy(count.begin(), count.end(), natural_.outerIndexPtr());
  std::vector<std::pair<int, double>> column;
  std::vector<int> next(count.begin(), count.end() - 1);
  for (int c = 0; c < n; ++c)
    for (int q = col[c]; q < col[c + 1]; ++q) {
      const int a = unknown(row[q]), b = unknown(c);
      const int dst = next[static_cast<std::size_t>(std::min(a, b))]++;
      natural_.innerIndexPtr()[dst] = std::max(a, b);
      natural_.valuePtr()[dst] = val[q];
    }
  for (int c = 0; c < n; ++c) {
    const int q0 = count[static_cast<std::size_t>(c)], q1 = count[static_cast<std::size_t>(c) + 1];
    column.clear();
    for (int q = q0; q < q1; ++q) column.emplace_back(natural_.innerIndexPtr()[q], natural_.valuePtr()[q]);
    std::sort(column.begin(), column.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (int q = q0; q < q1; ++q) {
      natural_.innerIndexPtr()[q] = column[static_cast<std::size_t>(q - q0)].first;
      natural_.valuePtr()[q] = column[static_cast<std::size_t>(q - q0)].second;
    }
  }
  return natural_;
}

const linalg::SolveReport& TangentSolver::factorize(const linalg::SparseMatrix& k) {
  if (pattern_ && &k == &pattern_->matrix() && pattern_->generation() != pattern_generation_)
    reorder();  // the pattern grew (contact pairs): ordered anew
  if (!use_iterative_) return factorize_direct(k);
  const auto t0 = std::chrono::steady_clock::now();
  SolveProfile& profile = solve_profile();
  SF_ASSERT(static_cast<Index>(group_.size()) == k.rows(), "one group per free unknown");
  const double factorize_before = profile.factorize_s;
  const bool same_pattern = k_.rows() == k.rows() && k_.nonZeros() == k.nonZeros();
  k_ = k;
  preconditioner_fresh_ = false;
  if (!preconditioner_ok_ || !same_pattern || refactor_next_)
    factorize_preconditioner();  // counted as a factorisation (factorize_direct)
  else
    ++profile.factorizations;
  iterative_report_ = linalg::SolveReport{};
  iterative_report_.n_rows = k.rows();
  iterative_report_.n_nonzeros = k.nonZeros();
  iterative_report_.used = active_ ? active_->kind() : linalg::SolverKind::kAuto;
  // A preconditioner that could not be factorised: the solves go to the direct LU.
  iterative_report_.status = linalg::SolveReport::Status::kOk;
  iterative_report_.reused_analysis = true;
  iterative_report_.factor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  profile.solver = std::string(mode_ == LinearMode::kIterativePly ? "gmres, per-ply preconditioner by "
                                                                  : "gmres, preconditioned by an earlier tangent's ") +
                   (active_ ? linalg::to_string(active_->kind()) : "none");
  profile.factorize_s = factorize_before + iterative_report_.factor_seconds;
  return iterative_report_;
}

// The preconditioner from the current tangent k_.
bool TangentSolver::factorize_preconditioner() {
  ++solve_profile().preconditioner_factorizations;
  const linalg::SolveReport& r =
      mode_ == LinearMode::kIterativePly ? factorize_direct(linalg::block_diagonal(k_, group_)) : factorize_direct(k_);
  preconditioner_ok_ = r.ok();
  preconditioner_fresh_ = true;
  refactor_next_ = false;
  return preconditioner_ok_;
}

const linalg::SolveReport& TangentSolver::factorize_direct(const linalg::SparseMatrix& k) {
  const auto t0 = std::chrono::steady_clock::now();
  SolveProfile& profile = solve_profile();
  ++profile.factorizations;
  struct AddTime {
    std::chrono::steady_clock::time_point t0;
    double& to;
    ~AddTime() { to += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
  } timer{t0, profile.factorize_s};
  const auto record = [&profile, this](const linalg::SolveReport& r) {
    if (!r.reused_analysis) {
      ++profile.analyses;
      profile.analyse_s += r.analyze_seconds;
    }
    profile.n = static_cast<long>(r.n_rows);
    profile.nnz = static_cast<long>(r.n_nonzeros);
    profile.factor_nnz = r.factor_nonzeros;
    profile.factor_flops = r.factor_flops;
    profile.solver = linalg::to_string(r.used);
    profile.ordering = r.used == linalg::SolverKind::kCholmod && !order_.empty() ? order_name_ : r.ordering;
  };
  if (!ordering_chosen_) {
    // UMFPACK's default AMD against METIS on the dome's start tangent (bench/
    // simform_dome_bench --factor-only): at 1944 unknowns AMD needs fewer flops (0.33
    // against 0.46 Gflop), at 10584 METIS (14.8 against 20.2 Gflop, 25 % less time), at
    // 40344 (20 x 20 bricks, 4 plies) see docs. CHOLMOD's default already tries both.
    ordering_chosen_ = true;
    for (linalg::LinearSolver* s : {general_.get(), lu_fallback_.get()})
      if (s && default_ordering() == linalg::Ordering::kDefault && s->kind() == linalg::SolverKind::kUmfpack &&
          k.rows() >= kMetisFrom)
        s->set_ordering(linalg::Ordering::kMetis);
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
  // The other solvers get the matrix in the natural order, as without the Cholesky's
  // layout (their own orderings, so the same results).
  const linalg::SparseMatrix& kn = natural(k);
  if (indefinite_) {
    const linalg::SolveReport& r = indefinite_->factorize(kn);
    record(r);
    ++profile.indefinite_factorizations;
    if (r.ok()) {
      active_ = indefinite_.get();
      return r;
    }
    // Singular or failed: the LU below says which.
  }
  if (lower_ && !linalg::reads_lower_triangle(general_->kind())) {
    // Both triangles for the LU; the same lower pattern expands to the same full one, so
    // its analysis is kept as well.
    expanded_ = kn.selfadjointView<Eigen::Lower>();
    const linalg::SolveReport& r = general_->factorize(expanded_);
    record(r);
    active_ = r.ok() ? general_.get() : nullptr;
    return r;
  }
  const linalg::SolveReport& r = general_->factorize(kn);
  record(r);
  if (r.ok() || !lu_fallback_) {
    active_ = r.ok() ? general_.get() : nullptr;
    return r;
  }
  // MUMPS's LU failed (singular to its pivoting, out of memory, ...): UMFPACK's, which
  // says which when it fails as well.
  ++n_lu_fallbacks_;
  ++profile.lu_fallbacks;
  const linalg::SolveReport& fr = lu_fallback_->factorize(kn);
  record(fr);
  active_ = fr.ok() ? lu_fallback_.get() : nullptr;
  return fr;
}

Eigen::MatrixXd TangentSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (use_iterative_) return solve_iterative(b);
  SF_ASSERT(active_ != nullptr, "TangentSolver::solve() needs a successful factorize()");
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd x = solve_direct(b);
  SolveProfile& profile = solve_profile();
  ++profile.solves;
  profile.solve_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return x;
}

Eigen::MatrixXd TangentSolver::solve_direct(const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (active_ == spd_.get() && !order_.empty()) {  // the matrix in the pattern's order
    const Index n = b.rows();
    Eigen::MatrixXd pb(n, b.cols());
    for (Index r = 0; r < n; ++r) pb.row(r) = b.row(order_[static_cast<std::size_t>(r)]);
    const Eigen::MatrixXd px = active_->solve(pb);
    Eigen::MatrixXd x(n, b.cols());
    for (Index r = 0; r < n; ++r) x.row(order_[static_cast<std::size_t>(r)]) = px.row(r);
    return x;
  }
  Eigen::MatrixXd x = active_->solve(b);
  if (active_ == indefinite_.get()) check_indefinite(b, x);
  if (lu_fallback_ && active_ == general_.get()) check_lu(b, x);
  return x;
}

double TangentSolver::refine(const linalg::LinearSolver& s, const Eigen::Ref<const Eigen::MatrixXd>& b,
                             Eigen::MatrixXd& x, long& refinements) const {
  // The largest relative residual over the columns (a zero column of b has x = 0 exactly).
  const auto worst = [&b](const Eigen::MatrixXd& r) {
    double w = 0.0;
    for (Index c = 0; c < b.cols(); ++c) {
      const double nb = b.col(c).norm();
      w = std::max(w, nb > 0.0 ? r.col(c).norm() / nb : r.col(c).norm());
    }
    return w;
  };
  Eigen::MatrixXd r = s.residual(b, x);
  double w = worst(r);
  for (int step = 0; step < kRefinementSteps && w > residual_tolerance_ && std::isfinite(w); ++step) {
    const Eigen::MatrixXd dx = s.solve(r);
    ++refinements;
    const Eigen::MatrixXd x_new = x + dx;
    Eigen::MatrixXd r_new = s.residual(b, x_new);
    const double w_new = worst(r_new);
    if (!(w_new < w)) break;  // refinement no longer helps
    x = x_new;
    r = std::move(r_new);
    w = w_new;
  }
  return w;
}

void TangentSolver::check_lu(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x) {
  SolveProfile& profile = solve_profile();
  ++profile.lu_checked_solves;
  const double w = refine(*general_, b, x, profile.lu_refinements);
  if (w <= residual_tolerance_) {
    profile.lu_worst_residual = std::max(profile.lu_worst_residual, w);
    return;
  }
  // Not good enough (or not finite): UMFPACK's LU of the same matrix, for this solve and
  // the rest of this tangent's.
  ++n_lu_fallbacks_;
  ++profile.lu_fallbacks;
  const linalg::SolveReport& lu = lu_fallback_->factorize(general_->matrix());
  if (!lu.ok()) {  // keep MUMPS's solution, the best there is; record how far off it is
    profile.lu_worst_residual = std::max(profile.lu_worst_residual, w);
    return;
  }
  active_ = lu_fallback_.get();
  x = lu_fallback_->solve(b);
}

void TangentSolver::check_indefinite(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x) {
  SolveProfile& profile = solve_profile();
  const double w = refine(*indefinite_, b, x, profile.residual_refinements);
  if (w <= residual_tolerance_) {
    profile.indefinite_worst_residual = std::max(profile.indefinite_worst_residual, w);
    return;
  }
  // The LDL^T's solution is not good enough (pivots too small for its threshold): the LU.
  ++n_residual_fallbacks_;
  ++profile.residual_fallbacks;
  expanded_ = indefinite_->matrix().selfadjointView<Eigen::Lower>();
  const linalg::SolveReport& lu = linalg::reads_lower_triangle(general_->kind())
                                      ? general_->factorize(indefinite_->matrix())
                                      : general_->factorize(expanded_);
  if (!lu.ok()) {  // keep the LDL^T's solution, the best there is; record how far off it is
    profile.indefinite_worst_residual = std::max(profile.indefinite_worst_residual, w);
    return;
  }
  active_ = general_.get();
  x = general_->solve(b);
}

Eigen::MatrixXd TangentSolver::solve_iterative(const Eigen::Ref<const Eigen::MatrixXd>& b) {
  const auto t0 = std::chrono::steady_clock::now();
  SolveProfile& profile = solve_profile();
  const linalg::Storage storage = lower_ ? linalg::Storage::kLower : linalg::Storage::kFull;
  linalg::GmresOptions options;
  options.tolerance = kTolerance;
  static const bool trace = std::getenv("SF_KRYLOV_TRACE") != nullptr;  // one line per GMRES solve
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(b.rows(), b.cols());
  for (Index c = 0; c < b.cols(); ++c) {
    Eigen::VectorXd xc = Eigen::VectorXd::Zero(b.rows());
    linalg::GmresReport r;
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (attempt == 1) {
        if (preconditioner_fresh_) break;  // a fresh one did not do: no use trying again
        factorize_preconditioner();
        if (!(r.relative_residual < 1.0)) xc.setZero();  // else GMRES goes on from the stale attempt's x
      }
      if (!preconditioner_ok_) continue;
      // A stale preconditioner gets kRefactorIterations: beyond them a fresh one is cheaper.
      options.max_iterations = preconditioner_fresh_ ? kMaxIterations : kRefactorIterations;
      const linalg::LinearSolver* m = active_;
      r = linalg::gmres(
          k_, storage, [m](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& y) { y = m->solve(v).col(0); },
          b.col(c), xc, options);
      ++profile.krylov_solves;
      profile.krylov_iterations += r.iterations;
      if (trace)
        std::fprintf(stderr, "tangent solve %ld (attempt %d): %s\n", profile.krylov_solves, attempt + 1,
                     r.brief().c_str());
      if (r.converged) break;
    }
    if (r.converged) {
      profile.krylov_worst_residual = std::max(profile.krylov_worst_residual, r.relative_residual);
      // Refactorise when the preconditioner has aged (the next solve would likely need more
      // still). By counts, not seconds: the run's path does not depend on the machine's load.
      if (r.iterations > kRefactorAfter) refactor_next_ = true;
      x.col(c) = xc;
      continue;
    }
    // The direct LU of the whole tangent.
    ++profile.direct_fallbacks;
    refactor_next_ = true;
    if (!fallback_) fallback_ = std::make_unique<TangentSolver>(fallback_kind_, fallback_unsymmetric_);
    const linalg::SolveReport& fr = fallback_->factorize_direct(k_);
    if (!fr.ok()) {
      x.col(c).setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    x.col(c) = fallback_->solve_direct(b.col(c));
  }
  profile.solve_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++profile.solves;
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
  make_solver(model);
  solver_->lay_out(*pattern_);
}

void TangentWorkspace::make_unsymmetric(const Model& model) {
  solver_ = std::make_unique<TangentSolver>(kind_, true);
  unsymmetric_ = true;
  lay_out(model);
  make_solver(model);
  solver_->lay_out(*pattern_);
}

std::vector<int> ply_groups(const Model& model, const std::vector<Index>& active_dofs) {
  // Dofs outside every body (none today) form a group of their own.
  std::vector<int> group(active_dofs.size(), model.n_bodies());
  for (std::size_t j = 0; j < group.size(); ++j) {
    const Index d = active_dofs[j];
    for (int b = 0; b < model.n_bodies(); ++b)
      if (d >= model.offset(b) && d < model.offset(b) + model.ply(b).n_dofs()) {
        group[j] = b;
        break;
      }
  }
  return group;
}

void TangentWorkspace::make_solver(const Model& model) {
  if (linear == LinearMode::kDirect) return;  // the direct solver made with the pattern
  std::vector<int> group = ply_groups(model, pattern_->active_dofs());
  solver_ = std::make_unique<TangentSolver>(kind_, unsymmetric_, linear, std::move(group));
}

void TangentWorkspace::lay_out(const Model& model) {
  const auto t0 = std::chrono::steady_clock::now();
  pattern_.reset();  // release the old tables before building the new ones
  pattern_ = std::make_unique<linalg::PatternAssembler>(model.make_pattern(is_free_, solver_->lower()));
  layout_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++layouts_;
}

}  // namespace sf::forming
