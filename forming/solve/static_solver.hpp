#pragma once
// Assembly of ply bricks into a model and the quasi-static Newton-Raphson solver.
//
// Model: one or more plies (bodies), each a PlyMesh with its Material. Global dofs are
// the plies' dofs (forming/model/ply_mesh.hpp: dof = 3 (4 node + d) + coord) one ply after
// the other: body b owns [offset(b), offset(b) + ply(b).n_dofs()). Unknowns are
// current POSITIONS x (not displacements), flattened like PlyMesh::flatten; the start
// of a solve is typically Model::reference_positions().
//
// Static problem at load factor lambda in [0, 1]:
//   r(x) = f_int(x) - lambda f_ext = 0 on the free dofs,
//   x_d  = x_start_d + lambda (target_d - x_start_d) on every prescribed dof d,
// with f_int = dPi_int/dx (assembled element forces through the element maps, so the
// arc-length scale factors are applied) and f_ext a dead load (N). Prescribed dofs may
// be any parameter: values AND derivative parameters.
//
// Newton: each load step starts with a predictor that moves the prescribed dofs to
// their new values and solves K_ff dx_f = -r_f - K_fp dx_p (consistent linearisation),
// then corrects with K_ff dx_f = -r_f until
//   |r_f| <= max(residual_tol_abs, residual_tol_rel * force_scale),
// force_scale = max(|f_int| over all dofs (includes the reactions), |lambda f_ext|),
// or until a correction is below 1e-14 of the largest |x_start| (the residual's
// round-off floor: a smaller correction cannot reduce it).
// Corrector steps are damped by a backtracking line search on |r_f| (optional). A step
// that fails (too many iterations, divergence, an inverted Gauss point, a singular
// tangent) is retried from the last converged state with half the load increment;
// after a step that converges in <= options.easy_iterations the increment grows by
// options.growth (capped at max_increment). Every loop is bounded: the solve ends
// with a report, never an endless loop, and returns the last converged state.
//
// Units: positions mm, forces N, stiffness N/mm (any consistent set).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/element/element.hpp"
#include "forming/material/material.hpp"
#include "forming/model/ply_mesh.hpp"

namespace sf::forming {

// Result of assembling the model at a state x.
struct Assembly {
  bool ok = true;        // false: an element reported an inverted point (see message)
  std::string message;   // empty when ok
  double energy = 0.0;   // internal energy, N mm
  VecX force;            // f_int, n_dofs, N
  linalg::SparseMatrix tangent;  // n_dofs x n_dofs, N/mm (empty unless asked for)
};

class Model {
 public:
  explicit Model(ElementRule rule = {});

  // Adds a ply; returns its body index. The material is shared (several plies may use
  // one law); for the TI law its fibre direction should be ply.fibre_direction().
  // `constraints`: element-mean incompressibility / fibre inextensibility of this ply
  // (forming/element/element.hpp ConstraintTerms: the flags and the penalties kappa, k_fibre;
  // its p and T are the starting multipliers of every element).
  int add_ply(PlyMesh ply, std::shared_ptr<const Material> material, const ConstraintTerms& constraints = {});

  // Element multipliers (pressure p and fibre tension T, MPa) of a constrained body.
  bool constrained(int body) const { return bodies_[body].constraints.active(); }
  const ConstraintTerms& constraints(int body) const { return bodies_[body].constraints; }
  const std::vector<double>& pressures(int body) const { return bodies_[body].p; }
  const std::vector<double>& tensions(int body) const { return bodies_[body].T; }
  void set_multipliers(int body, std::vector<double> p, std::vector<double> T);

  // Per element of `body` at positions x: mean constraint values and the effective
  // multipliers p_eff = p - kappa g_J, T_eff = T + k_fibre g_T (the Uzawa update).
  struct ConstraintState {
    double g_J = 0.0, g_T = 0.0, p_eff = 0.0, T_eff = 0.0, volume = 0.0;
  };
  std::vector<ConstraintState> constraint_state(int body, const Eigen::Ref<const VecX>& x) const;

  int n_bodies() const { return static_cast<int>(bodies_.size()); }
  Index n_dofs() const { return n_dofs_; }
  const PlyMesh& ply(int body) const { return bodies_[body].ply; }
  const Material& material(int body) const { return *bodies_[body].material; }
  Index offset(int body) const { return bodies_[body].offset; }
  // Global dof of (body, ply node, parameter d, coordinate).
  Index dof(int body, Index node, int d, int coord) const {
    return offset(body) + PlyMesh::dof(node, d, coord);
  }
  const ElementRule& rule() const { return rule_; }

  // Global dofs of brick e of `body`, expanded per (function, map term, coordinate):
  // element-vector entry local[a] (= 3 k + i) contributes coefs[a] times to global dof
  // dofs[a]; repeated dofs (collapsed elements) are summed by the caller.
  struct ElementDofs {
    std::vector<Index> dofs;
    std::vector<double> coefs;
    std::vector<int> local;
  };
  ElementDofs element_dofs(int body, Index e) const;

  // Reference positions of all bodies (n_dofs, mm).
  VecX reference_positions() const;
  // Dofs no element uses (e.g. the cross parameter of a collapsed apex): the solver fixes them.
  std::vector<bool> used_dofs() const;

  // Internal energy, force and (when want_tangent) tangent at positions x (n_dofs).
  Assembly assemble(const Eigen::Ref<const VecX>& x, bool want_tangent) const;

  // Deformation gradient at every Gauss point of every brick of `body` (element-major,
  // points in ElementRule::brick() order), for checks and outputs.
  std::vector<Mat3> deformation_gradients(int body, const Eigen::Ref<const VecX>& x) const;

 private:
  struct Body {
    PlyMesh ply;
    std::shared_ptr<const Material> material;
    Index offset = 0;
    ConstraintTerms constraints;  // flags and penalties
    std::vector<double> p, T;     // per element multipliers (when constrained)
  };
  ConstraintTerms element_constraints(const Body& b, Index e) const;
  ElementRule rule_;
  quadrature::TensorRule<3> brick_rule_;
  std::vector<Body> bodies_;
  Index n_dofs_ = 0;
};

// The free dofs of a solve, in ascending order, and the n x nf selection matrix S
// (column j = unit vector of free dof j): K_ff = S^T K S, x += S dx_f.
struct FreeDofs {
  std::vector<Index> index;
  linalg::SparseMatrix select;
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

// A prescribed dof: its position at load factor 1 (mm; for derivative parameters the
// arc-length derivative, dimensionless).
struct PrescribedDof {
  Index dof = -1;
  double value = 0.0;
};

struct StaticOptions {
  double initial_increment = 1.0;  // first load-factor increment, (0, 1]
  double max_increment = 1.0;      // cap after regrowth, (0, 1]
  double min_increment = 1e-6;     // cut back below this -> kStepFailed
  double growth = 1.5;             // increment growth after an easy step, >= 1
  int easy_iterations = 5;         // ... i.e. one converging in at most this many iterations
  int max_iterations = 25;         // Newton iterations per step (predictor included)
  int max_steps = 1000;            // attempted steps in total (converged + cut back)
  double residual_tol_rel = 1e-10; // relative to force_scale
  double residual_tol_abs = 0.0;   // N
  double divergence_factor = 1e8;  // |r| growing past this times the step's first |r| fails
  bool line_search = true;
  int max_line_search = 8;         // halvings of the corrector step
  linalg::SolverKind linear_solver = linalg::SolverKind::kAuto;
  // Throws sf::InputError naming the option ("static solver max_iterations: ...").
  void validate() const;
};

// One attempted load step.
struct StepRecord {
  double load_factor = 0.0;  // target of the step
  double increment = 0.0;
  bool converged = false;
  int iterations = 0;                  // Newton solves (predictor included)
  std::vector<double> residual_norms;  // |r_f| after the predictor and after each corrector
  std::vector<double> step_lengths;    // line-search factor of each corrector (1 = full)
  std::string failure;                 // why it failed (empty when converged)
};

struct StaticReport {
  enum class Status {
    kConverged,     // lambda = 1 reached
    kStepFailed,    // cut back below min_increment, or max_steps reached; see message
    kInvalidStart,  // the starting state is not admissible (inverted element) or a
                    // prescribed dof is out of range
  };
  Status status = Status::kStepFailed;
  std::string message;
  double load_factor = 0.0;  // of the returned (last converged) state
  int n_converged_steps = 0;
  int n_cutbacks = 0;
  int total_iterations = 0;
  double force_scale = 0.0;  // of the last converged state
  std::vector<StepRecord> steps;  // all attempted steps, in order
  bool ok() const { return status == Status::kConverged; }
  // One line, e.g. "converged: lambda 1 in 4 steps (0 cut-backs), 17 Newton iterations, |r| 3.1e-15".
  std::string brief() const;
};

std::string to_string(StaticReport::Status status);

struct StaticResult {
  VecX positions;  // last converged state (n_dofs, mm)
  VecX reactions;  // f_int - lambda f_ext there (zero on free dofs up to the tolerance), N
  StaticReport report;
};

// External force at load factor lambda and positions x, and (when asked for) its
// derivative d f_ext / dx (empty when the load does not depend on x). See
// forming/model/loads.hpp for the loads that build one.
struct ExternalLoad {
  VecX force;                    // n_dofs, N
  linalg::SparseMatrix tangent;  // n_dofs x n_dofs or empty, N/mm
};
using LoadFunction = std::function<ExternalLoad(double lambda, const VecX& x, bool want_tangent)>;

// Augmented Lagrangian (Uzawa) iterations for constrained bodies: solve, then set every
// element's multipliers to their effective values, until max |g_J|, |g_T| <= tolerance
// (or max_updates). Without constrained bodies this is one solve_static().
struct UzawaOptions {
  double tolerance = 1e-8;  // on the element-mean constraint values (dimensionless)
  int max_updates = 30;
};
struct UzawaReport {
  int updates = 0;
  double max_g_J = 0.0, max_g_T = 0.0;  // after the last solve
  bool converged = true;
};

// Solves the static problem from x_start (n_dofs). f_ext: n_dofs dead load at lambda = 1
// (empty = none). Dofs no element uses are held at their start values.
StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const VecX& f_ext,
                          const StaticOptions& options = {});
// The same with a general load r(x) = f_int(x) - load(lambda, x).force and tangent
// K_int - load.tangent. `unsymmetric`: the load's tangent is not symmetric (follower
// pressure), so the linear solves use an unsymmetric factorisation (UMFPACK).
StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                          bool unsymmetric, const StaticOptions& options = {});
// solve_static() repeated with Uzawa updates of `model`'s multipliers (see UzawaOptions).
// Each repeat starts from the previous solution with the same targets and loads.
StaticResult solve_static_constrained(Model& model, const Eigen::Ref<const VecX>& x_start,
                                      const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                      bool unsymmetric, const StaticOptions& options, const UzawaOptions& uzawa,
                                      UzawaReport* report = nullptr);

}  // namespace sf::forming
