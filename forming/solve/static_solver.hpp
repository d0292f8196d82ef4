#pragma once
// The quasi-static Newton-Raphson solver for a Model (forming/model/model.hpp).
//
// Static problem at load factor lambda in [0, 1]:
//   r(x) = f(x) - f_ext(lambda, x) = 0 on the free dofs,
//   x_d  = x_start_d + lambda (target_d - x_start_d) on every prescribed dof d,
// with f = dPi/dx the model's assembled force (elements and interactions, through the
// element maps, so the arc-length scale factors are applied) and f_ext the load
// (forming/model/loads.hpp; a dead load lambda f_ext in the simplest form). Prescribed
// dofs may be any parameter: values AND derivative parameters.
//
// Newton: each load step starts with a predictor that moves the prescribed dofs to
// their new values and solves K_ff dx_f = -r_f - K_fp dx_p (consistent linearisation),
// damped by the line search below (the full predictor of a tool moved a whole increment
// into a ply of near-inextensible fibres overshoots far),
// then corrects with K_ff dx_f = -r_f until
//   |r_f| <= max(residual_tol_abs, residual_tol_rel * force_scale),
// force_scale = max(|f_int| over all dofs (includes the reactions), |lambda f_ext|),
// or until a correction is below 1e-14 of the largest |x_start| (the residual's
// round-off floor: a smaller correction cannot reduce it).
// Corrector steps are damped by a line search (optional): a trial is taken when |r_f|
// fell, or, along a descent direction of the potential, when the slope dx . r_f fell to
// 0.8 of its start and |r_f| stayed below 1000 max(|r_f|, force scale); a rejected
// trial is followed by the secant root of the slope (or half the step). A step whose
// last five corrections were all damped below 1/2 without halving |r_f| is cut back at
// once (after at least eight iterations). A step
// that fails (too many iterations, divergence, an inverted Gauss point, a singular
// tangent) is retried from the last converged state with half the load increment
// (with options.give_up_after, only so many times in the solve);
// after a step that converges in <= options.easy_iterations, or after
// options.regrow_after steps in a row converged since the last cut-back or growth, the
// increment grows by options.growth (capped at max_increment); with a shared options.workspace (a run's
// load steps) the next solve starts with the increment this one ended with. Every loop is bounded: the solve ends
// with a report, never an endless loop, and returns the last converged state.
//
// Units: positions mm, forces N, stiffness N/mm (any consistent set).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/solve/step_history.hpp"

namespace sf::forming {

class TangentWorkspace;

// Process time of a quasi-static solve (forming/solve/stepper.hpp sets it per load step):
// the solve's load factor lambda in [0, 1] is the time start + lambda (end - start), s,
// which interactions see (forming/model/interaction.hpp: a tool moves with it). Their
// rates are finite differences from the solve's last converged state: before the first,
// `previous` at `previous_time` when given, else x_start at `start`; after each converged
// sub-step (cut-backs), that state. With end == start the time stands still and the
// rates keep coming from the first (the repeats of a step for multiplier updates).
// Default: time 0 and no rates.
struct ProcessClock {
  double start = 0.0;              // s
  double end = 0.0;                // s, >= start
  const VecX* previous = nullptr;  // n_dofs, mm, or null
  double previous_time = 0.0;      // s
  double at(double lambda) const { return start + lambda * (end - start); }
};

struct StaticOptions {
  double initial_increment = 1.0;  // first load-factor increment, (0, 1]
  double max_increment = 1.0;      // cap after regrowth, (0, 1]
  double min_increment = 1e-6;     // cut back below this -> kStepFailed
  double growth = 1.5;             // increment growth after an easy step, >= 1
  int easy_iterations = 5;         // ... i.e. one converging in at most this many iterations
  // ... or after this many steps in a row converged at one increment (0: never). Under
  // contact a sub-step rarely converges in easy_iterations (the active set wanders for
  // 5-15 iterations at any size: the matched-die bends), so without it one cut-back to 1/8
  // kept every later step of the run in eighths.
  int regrow_after = 2;
  int max_iterations = 25;         // Newton iterations per step (predictor included)
  // Start each solve's first predictor from the start state moved by the previous
  // solve's increment, scaled to this solve's process-time span (kept in the workspace):
  // a tool that keeps moving then meets plies that already moved with it, instead of
  // the whole stroke as penetration. Off: the predictor starts at the start state.
  bool extrapolate = false;
  int max_steps = 1000;             // attempted steps in total (converged + cut back)
  // Give up early: a solve in which this many sub-steps have failed (the increment
  // halved each time) ends at once as failed (kStepFailed, at its last converged
  // sub-step) instead of cutting back on to min_increment; 0: off. Branch switching sets
  // it (forming/solve/stepper.hpp): a stall beside a bifurcation is not passed by ever
  // smaller increments (Newton creeps towards it in sub-steps of 1e-3 of a step, each
  // failure up to max_iterations), and a switch from the last converged state costs less.
  int give_up_after = 0;
  double residual_tol_rel = 1e-10;  // relative to force_scale
  double residual_tol_abs = 0.0;    // N
  double divergence_factor = 1e8;   // |r| growing past this times the step's first |r| fails
  bool line_search = true;
  int max_line_search = 8;  // halvings of the corrector step
  // With the line search (watchdog): a corrector's full step that the line search would
  // damp is taken when |r_f| grows at most 100 times; if |r_f| is not below its value
  // before that step within 3 iterations, Newton returns there and damps, without the
  // watchdog for the rest of the load step (static_solver.cpp, LoadStepping::correct).
  bool watchdog = true;
  linalg::SolverKind linear_solver = linalg::SolverKind::kAuto;
  ProcessClock clock;  // time and rates the interactions see
  // Called after every converged sub-step while the clock runs, with the state the
  // interactions' rates started from and its time, and the state reached and its time
  // (s): the stepper sums the stabilisation's dissipation (forming/solve/stabilisation.hpp).
  std::function<void(const VecX& from, double from_time, const VecX& to, double to_time)> on_substep;
  // Tangent pattern and factorisation kept between solves of the same model (a run's
  // load steps, forming/solve/tangent_solver.hpp); null: laid out for this solve only.
  std::shared_ptr<TangentWorkspace> workspace;
  // Throws sf::InputError naming the option ("static solver max_iterations: ...").
  void validate() const;
};

// The load steps of a solve (forming/solve/step_history.hpp: status, message, counters,
// every attempted step with target = load factor, last_residual()).
struct StaticReport : StepHistory {
  double load_factor = 0.0;  // of the returned (last converged) state
  double force_scale = 0.0;  // of the last converged state
  // One line, e.g. "converged: lambda 1 in 4 steps (0 cut-backs), 17 Newton iterations, |r| 3.1e-15".
  std::string brief() const;
};

struct StaticResult {
  VecX positions;  // last converged state (n_dofs, mm)
  VecX reactions;  // f_int - lambda f_ext there (zero on free dofs up to the tolerance), N
  StaticReport report;
};

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
                          const std::vector<PrescribedDof>& prescribed, const LoadFunction& load, bool unsymmetric,
                          const StaticOptions& options = {});
// solve_static() repeated with Uzawa updates of `model`'s multipliers (see UzawaOptions).
// Each repeat starts from the previous solution with the same targets and loads.
StaticResult solve_static_constrained(Model& model, const Eigen::Ref<const VecX>& x_start,
                                      const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                      bool unsymmetric, const StaticOptions& options, const UzawaOptions& uzawa,
                                      UzawaReport* report = nullptr);

}  // namespace sf::forming
