#pragma once
// Pieces of a Newton iteration shared by the static, dynamic and arc-length solvers:
// the free dofs of a solve (and the selection matrix that restricts a vector or a
// matrix to them) and the linear solver of the Newton tangent.
#include <memory>
#include <string>
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
// while it is positive definite, as it is at stable equilibria. Where Cholesky breaks
// down (past a limit point, under compressive instability, the dome's flat start) the
// symmetric indefinite LDL^T of MUMPS (threshold 1x1/2x2 pivoting) factorises the same
// lower triangle, and each of its solutions is checked: |K dx - b| <= kResidualTolerance |b|,
// after up to kRefinementSteps steps of iterative refinement; a solution that fails the
// check, or an LDL^T that fails, goes to UMFPACK's LU (symmetric strategy) on the matrix
// expanded from the lower triangle, the path of builds without MUMPS (and CHOLMOD's
// simplicial LDL^T without UMFPACK). After a breakdown the next few factorisations skip
// Cholesky. An explicit solver kind goes straight to that one, with both triangles stored
// unless the kind reads only the lower one. Unsymmetric tangents (follower loads, friction:
// the viscous inter-ply slip of the forming cases) with kAuto go to MUMPS's multifrontal LU
// when MUMPS is built in (0.72x of UMFPACK's processor time a factorisation on the dome's
// tangent, solves 6x faster at 40k unknowns), each of its solutions checked as the LDL^T's
// are (|K dx - b| <= kResidualTolerance |b| after up to kRefinementSteps refinement steps);
// a failed MUMPS factorisation or a solution that fails the check is done by UMFPACK's LU
// (METIS ordering from kMetisFrom unknowns), the only LU of builds without MUMPS.
// Each back end keeps its symbolic analysis while the pattern stays the same (across
// iterations and, with a solver kept between solves, load steps).
//
// Iterative mode (the case key `solver: {linear: iterative}`): solve()
// runs restarted GMRES (common/linalg/krylov.hpp) on the whole K_ff, preconditioned by a
// factorisation made by the direct path above and kept over Newton iterations (and load
// steps) while it still works:
//   kIterative     the factorisation of an earlier tangent of the run (K_ff as it was at
//                  the last refactorisation): near the current one, so GMRES needs a few
//                  iterations while Newton's tangents change little;
//   kIterativePly  (benchmarks only, bench/simform_dome_bench --linear iterative-ply; not a
//                  case key: it fails under penalty contact) the block-diagonal part of
//                  K_ff, one block per ply (body): each ply's own stiffness and the diagonal
//                  part of its contact, much smaller factors than the laminate's, the contact
//                  coupling between plies left to the iteration (measured: hundreds of GMRES
//                  iterations or the direct fallback under stiff penalty contact, see docs).
// Tolerance: |K dx + r| <= kTolerance |r| (1e-10, below the Newton tolerances of the cases,
// so Newton converges as with the direct solve). The preconditioner is refactorised by the
// next factorize() when the last solve needed more than kRefactorAfter GMRES iterations
// (20: at the dome's sizes about half a factorisation's time; counts, not seconds, so the
// run does not depend on the machine's load) and whenever the pattern changes;
// a solve whose stale preconditioner has not converged within kRefactorIterations
// refactorises it at once and continues from the iterate reached; one that a fresh
// preconditioner does not bring to the tolerance in kMaxIterations is done by the direct
// LU of the whole K_ff (counted in the solve profile). The preconditioner's UMFPACK solves skip iterative refinement.
// kAuto: direct (measured: data/forming/processes/README.md, "Iterative solves of the
// tangent"; the iterative mode did not pay clearly at any size measured).
enum class LinearMode { kAuto, kDirect, kIterative, kIterativePly };
// "auto", "direct", "iterative", "iterative-ply".
std::string to_string(LinearMode mode);
// Inverse of to_string(LinearMode); sf::InputError otherwise (message starts with `where`).
// Accepts "iterative-ply" (benchmarks); the case reader does not.
LinearMode parse_linear_mode(const std::string& name, const std::string& where = "");

class TangentSolver {
 public:
  // group: the ply (any small integer) of each free unknown (the order of K_ff): kAuto
  // reads its size, kIterativePly its values (a single group: kIterative).
  TangentSolver(linalg::SolverKind kind, bool unsymmetric, LinearMode mode = LinearMode::kDirect,
                std::vector<int> group = {});
  // True when factorize() expects the lower triangle only.
  bool lower() const { return lower_; }
  // Lays `pattern` (made for this solver: lower() storage) out for the direct Cholesky:
  // the fill-reducing order of its natural pattern (the ordering factorize() would choose)
  // becomes the pattern's order (PatternAssembler::set_order), so CHOLMOD factorises
  // pattern.matrix() in place: no copy of it, no permuted copy, no value map. The pattern
  // must outlive the solver's use of it (TangentWorkspace keeps both); factorize() then
  // takes pattern.matrix() (or any matrix in the same order), orders anew when the pattern
  // has grown, and solve() takes and returns vectors in the natural order as always. The
  // indefinite and LU fallbacks get the matrix back in the natural order (a copy, made
  // only when Cholesky fails). False (the pattern left in, or put back to, the natural
  // order) for the iterative mode, unsymmetric tangents and builds without CHOLMOD.
  bool lay_out(linalg::PatternAssembler& pattern);
  const linalg::SolveReport& factorize(const linalg::SparseMatrix& k);
  // dx with K dx = b for the last factorize()d K. Not const: a solution that fails its
  // residual check factorises the LU fallback, and an aged preconditioner is refactorised.
  Eigen::MatrixXd solve(const Eigen::Ref<const Eigen::MatrixXd>& b);
  // True when the last factorize() set up the iterative path (not the direct one).
  bool iterative() const { return use_iterative_; }
  // Factorisations that fell back to the indefinite solver so far.
  int n_indefinite() const { return n_indefinite_; }
  // Solves of the symmetric indefinite solver whose residual check sent them to the LU.
  int n_residual_fallbacks() const { return n_residual_fallbacks_; }
  // Factorisations and solves of an unsymmetric tangent that MUMPS's LU passed to UMFPACK
  // (its factorisation failed, or a solution failed the residual check).
  int n_lu_fallbacks() const { return n_lu_fallbacks_; }
  // The unsymmetric tangent's primary LU (MUMPS) when it has a fallback (UMFPACK), else
  // null: tests set limits on it (LinearSolver::set_memory_limit) to make it fail.
  linalg::LinearSolver* checked_lu() { return lu_fallback_ ? general_.get() : nullptr; }
  // A solution of the indefinite path is accepted when |K dx - b| <= kResidualTolerance |b|
  // (the GMRES tolerance below), after at most kRefinementSteps refinement steps.
  static constexpr double kResidualTolerance = 1e-10;
  static constexpr int kRefinementSteps = 2;
  // Another tolerance for that check (tests: 0 sends every such solve to the LU).
  void set_residual_tolerance(double tolerance) { residual_tolerance_ = tolerance; }
  // The back end that did the last successful factorisation (null before one).
  const linalg::LinearSolver* active() const { return active_; }
  // Fill-reducing ordering of the Newton tangents' solvers made from now on (process-wide;
  // linalg::Ordering::kDefault unless changed: CHOLMOD's AMD-then-METIS choice, UMFPACK's
  // AMD). For benchmarks comparing orderings (bench/simform_dome_bench.cpp --ordering).
  static void set_default_ordering(linalg::Ordering ordering);
  static linalg::Ordering default_ordering();

 private:
  const linalg::SolveReport& factorize_direct(const linalg::SparseMatrix& k);
  // The ordering of pattern_ from its natural pattern, and the pattern laid out in it.
  void reorder();
  // k (in the order order_) in the natural order: k itself when order_ is empty, else natural_.
  const linalg::SparseMatrix& natural(const linalg::SparseMatrix& k);
  bool factorize_preconditioner();
  Eigen::MatrixXd solve_iterative(const Eigen::Ref<const Eigen::MatrixXd>& b);
  // The active direct solver's solution, checked (and redone by the fallback) as its path says.
  Eigen::MatrixXd solve_direct(const Eigen::Ref<const Eigen::MatrixXd>& b);
  // Up to kRefinementSteps steps of iterative refinement of x (K x = b) with solver s while
  // |K x - b| > residual_tolerance_ |b|; returns the largest relative residual left.
  double refine(const linalg::LinearSolver& s, const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x,
                long& refinements) const;
  // The indefinite path's residual check and refinement of x (K x = b); LU when it fails.
  void check_indefinite(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x);
  // The same for MUMPS's LU of an unsymmetric tangent; UMFPACK when it fails.
  void check_lu(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& x);
  linalg::SolverKind fallback_kind_ = linalg::SolverKind::kAuto;
  bool fallback_unsymmetric_ = false;
  // spd_: Cholesky; indefinite_: symmetric indefinite LDL^T (MUMPS; null without it);
  // general_: the LU (or whatever an explicit kind or an unsymmetric tangent asks for);
  // lu_fallback_: UMFPACK's LU behind general_ when that is MUMPS's for an unsymmetric
  // tangent (kAuto with MUMPS built in), null otherwise.
  std::unique_ptr<linalg::LinearSolver> spd_, indefinite_, general_, lu_fallback_;
  // Iterative mode: the tangent (a copy: the caller reassembles in place), the groups, the
  // preconditioner's state and a direct solver for the fallback (made when first needed).
  LinearMode mode_ = LinearMode::kDirect;
  std::vector<int> group_;
  bool use_iterative_ = false;
  linalg::SparseMatrix k_;
  linalg::SolveReport iterative_report_;
  bool preconditioner_ok_ = false;                // the block factorisation is usable
  bool preconditioner_fresh_ = false;             // it was made from the current k_
  bool refactor_next_ = false;                    // the next factorize() refactorises it
  std::unique_ptr<TangentSolver> fallback_;       // direct solver of the whole K_ff
  static constexpr int kRefactorIterations = 40;  // GMRES iterations allowed a stale preconditioner
  static constexpr int kRefactorAfter = 20;       // more in a solve: refactorise for the next
  static constexpr int kMaxIterations = 400;      // and a fresh one
  static constexpr double kTolerance = 1e-10;     // GMRES: |K dx + r| <= kTolerance |r|
  const linalg::LinearSolver* active_ = nullptr;
  bool lower_ = false;
  // lay_out(): the pattern laid out in the Cholesky's order, its generation then, that
  // order (row r of the matrices factorize() gets is unknown order_[r]; empty: natural),
  // the ordering that made it, the natural-order copy for the fallbacks.
  linalg::PatternAssembler* pattern_ = nullptr;
  int pattern_generation_ = -1;
  std::vector<int> order_;
  std::string order_name_;
  linalg::Ordering spd_ordering_ = linalg::Ordering::kDefault;
  linalg::SparseMatrix natural_;
  // From this many unknowns up the LU orders by METIS (nested dissection) rather than
  // UMFPACK's AMD, unless set_default_ordering() chose one.
  static constexpr Index kMetisFrom = 5000;
  bool ordering_chosen_ = false;
  linalg::SparseMatrix expanded_;  // both triangles of a lower-stored tangent, for an LU fallback
  int skip_cholesky_ = 0;          // after a breakdown, the next few factorisations go to general_
  int n_indefinite_ = 0;
  int n_residual_fallbacks_ = 0;
  int n_lu_fallbacks_ = 0;
  double residual_tolerance_ = kResidualTolerance;
};

// The body (ply) of each of the unknowns `active_dofs` (global dofs, the order of K_ff):
// the groups of TangentSolver's iterative mode.
std::vector<int> ply_groups(const Model& model, const std::vector<Index>& active_dofs);

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
  // Direct or iterative solves of the tangent (the case key `solver: {linear: ...}`); read
  // by the next prepare() that lays out anew.
  LinearMode linear = LinearMode::kAuto;
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
  void make_solver(const Model& model);
  std::unique_ptr<linalg::PatternAssembler> pattern_;
  int layouts_ = 0;
  double layout_seconds_ = 0.0;
};

}  // namespace sf::forming
