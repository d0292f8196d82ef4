#pragma once
// Pieces of a Newton iteration shared by the static, dynamic and arc-length solvers:
// the free dofs of a solve (and the selection matrix that restricts a vector or a
// matrix to them) and the linear solver of the Newton tangent.
#include <memory>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/pattern_assembler.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::forming {

class Model;

// The free dofs of a solve, in ascending order, and the n x nf selection matrix S
// (column j = unit vector of free dof j): K_ff = S^T K S, x += S dx_f.
struct FreeDofs {
  std::vector<Index> index;
  std::vector<bool> is_free;
  linalg::SparseMatrix select;
  FreeDofs() = default;
  explicit FreeDofs(const std::vector<bool>& free);
  Index size() const { return static_cast<Index>(index.size()); }
  VecX restrict(const VecX& v) const;     // the free entries of v (n_dofs)
  VecX expand(const VecX& v_free) const;  // n_dofs, zero on the other dofs
};

// Linear solves with a Newton tangent K_ff as Model::assemble_into lays it out
// (linalg::PatternAssembler). With kAuto and a symmetric tangent the matrix is stored as
// its lower triangle (lower() is true) and factorised by supernodal Cholesky (CHOLMOD)
// while it is positive definite, as it is at stable equilibria; where Cholesky breaks
// down (past a limit point, under compressive instability, the dome's flat start) by
// UMFPACK's LU with its symmetric strategy on the matrix expanded from that lower
// triangle (CHOLMOD's simplicial LDL^T without SuiteSparse's UMFPACK): measured on the
// dome's start tangent, CHOLMOD's LDL^T (simplicial, no BLAS, no pivoting) took 9x the
// LU's time at 10584 unknowns. After a breakdown the next few factorisations go to the
// fallback directly. Unsymmetric tangents (follower loads, friction: the viscous
// inter-ply slip of the forming cases) and an explicit solver kind go straight to that
// one (kAuto: UMFPACK), with both triangles stored unless the kind reads only the lower
// one.
// Each back end keeps its symbolic analysis while the pattern stays the same (across
// iterations and, with a solver kept between solves, load steps).
class TangentSolver {
 public:
  TangentSolver(linalg::SolverKind kind, bool unsymmetric);
  // True when factorize() expects the lower triangle only.
  bool lower() const { return lower_; }
  const linalg::SolveReport& factorize(const linalg::SparseMatrix& k);
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b) const;
  // Factorisations that fell back to the indefinite solver so far.
  int n_indefinite() const { return n_indefinite_; }
  // The back end that did the last successful factorisation (null before one).
  const linalg::LinearSolver* active() const { return active_; }
  // Fill-reducing ordering of the Newton tangents' solvers made from now on (process-wide;
  // linalg::Ordering::kDefault unless changed: CHOLMOD's AMD-then-METIS choice, UMFPACK's
  // AMD). For benchmarks comparing orderings (bench/simform_dome_bench.cpp --ordering).
  static void set_default_ordering(linalg::Ordering ordering);
  static linalg::Ordering default_ordering();

 private:
  std::unique_ptr<linalg::LinearSolver> spd_, general_;
  const linalg::LinearSolver* active_ = nullptr;
  bool lower_ = false;
  // From this many unknowns up the LU orders by METIS (nested dissection) rather than
  // UMFPACK's AMD, unless set_default_ordering() chose one.
  static constexpr Index kMetisFrom = 5000;
  bool ordering_chosen_ = false;
  linalg::SparseMatrix expanded_;  // both triangles of a lower-stored tangent, for an LU fallback
  int skip_cholesky_ = 0;          // after a breakdown, the next few factorisations go to general_
  int n_indefinite_ = 0;
};

// The Newton tangent's pattern (scatter tables) and its solver (symbolic analysis)
// kept between solves of one model: the load steps of a run (forming/solve/stepper.hpp),
// the repeats of a step for multiplier updates, the output intervals of a dynamic run.
// prepare() lays them out anew only when the model, its dof and element counts, the
// free dofs, the symmetry or the solver kind differ from the last solve's; contact pairs
// that appear later grow the kept pattern (linalg::PatternAssembler::flush), after which
// the solver analyses the grown pattern once. Not thread-safe: one solve at a time.
class TangentWorkspace {
 public:
  // Pattern and solver for a solve of `model` with these free dofs (n_dofs flags).
  void prepare(const Model& model, const std::vector<bool>& is_free, linalg::SolverKind kind, bool unsymmetric);
  TangentSolver& solver() { return *solver_; }
  linalg::PatternAssembler& pattern() { return *pattern_; }
  // Replaces the solver (and so the storage) by an unsymmetric one, keeping the model:
  // a load whose tangent turned out unsymmetric.
  void make_unsymmetric(const Model& model);  // may throw sf::InputError (as TangentSolver)
  // True when the last prepare()/make_unsymmetric() was for `model` with an unsymmetric solver.
  bool unsymmetric_for(const Model& model) const { return solver_ && model_ == &model && unsymmetric_; }
  // The load-factor increment (fraction of a solve's load) the last static solve would
  // have taken next; the next solve of the run starts with it (0: none yet).
  double next_increment = 0.0;
  // The increment of positions the last static solve made and its process-time span
  // (StaticOptions::extrapolate); empty: none yet.
  VecX last_increment;
  double last_span = 0.0;
  // How many times prepare() laid the pattern out (1 for a run whose structure stays).
  int layouts() const { return layouts_; }
  // Seconds spent laying patterns out, in total.
  double layout_seconds() const { return layout_seconds_; }

 private:
  void lay_out(const Model& model);
  const Model* model_ = nullptr;
  Index n_dofs_ = -1;
  std::size_t n_elements_ = 0;
  std::vector<bool> is_free_;
  linalg::SolverKind kind_ = linalg::SolverKind::kAuto;
  bool unsymmetric_ = false;
  std::unique_ptr<TangentSolver> solver_;
  std::unique_ptr<linalg::PatternAssembler> pattern_;
  int layouts_ = 0;
  double layout_seconds_ = 0.0;
};

}  // namespace sf::forming
