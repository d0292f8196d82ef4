#pragma once
// Implicit dynamics with inertia for the forming solver: a generalised-alpha time
// integrator (HHT-alpha and Newmark as special cases) with a Newton solve per step,
// automatic time-step cut-back and regrowth. The consistent mass matrix comes from
// forming/solve/mass.hpp.
//
// Units (consistent set): lengths mm, time s, mass t (tonne), density t/mm^3, so that
// force = t mm/s^2 = N, energy N mm, stiffness N/mm, mass matrix t, velocity mm/s,
// acceleration mm/s^2. (Steel 7.85e-9 t/mm^3; a dry carbon ply ~1.5e-9 t/mm^3.)
//
// Unknowns and layout are those of Model (forming/model/model.hpp): x = current
// POSITIONS (n_dofs, flattened like PlyMesh::flatten, derivative parameters included),
// v = dx/dt, a = d2x/dt2 (the derivative parameters' rates are those of the arc-length
// derivatives: 1/s and 1/s^2).
//
// Time integration (Chung & Hulbert 1993; notes/forming-verification.md section 3.3):
//   Newmark:   x_{n+1} = x_n + dt v_n + dt^2 [(1/2 - beta) a_n + beta a_{n+1}]
//              v_{n+1} = v_n + dt [(1 - gamma) a_n + gamma a_{n+1}]
//   balance at the intermediate point (free dofs):
//     R(x_{n+1}) = M a_{n+1-am} + f_int(x_{n+1-af}) - f_ext(t_{n+1-af}, x_{n+1-af}) = 0,
//     y_{n+1-a} = (1 - a) y_{n+1} + a y_n   for y = x, a, t (a = af or am).
//   Parameters (IntegratorParameters):
//     generalised-alpha, rho_inf in [0, 1]:
//       am = (2 rho - 1)/(rho + 1), af = rho/(rho + 1),
//       gamma = 1/2 - am + af, beta = (1 - am + af)^2 / 4;
//       rho_inf = 1: (am, af, gamma, beta) = (1/2, 1/2, 1/2, 1/4): no numerical
//       dissipation (for a linear system the trapezoidal rule: energy conserved, relative
//       period error ~ (omega dt)^2/12); rho_inf = 0: asymptotic annihilation.
//     HHT-alpha, alpha in [-1/3, 0]: am = 0, af = -alpha, gamma = (1 - 2 alpha)/2,
//       beta = (1 - alpha)^2/4. Note: f_int is evaluated at the interpolated positions
//       x_{n+1-af} (the generalised-alpha form) rather than interpolating f_int(x_n) and
//       f_int(x_{n+1}) as in the original HHT paper; both agree for a linear system.
//     Newmark(beta, gamma): am = af = 0.
//   These sign conventions are Chung-Hulbert's (am, af >= 0 weight the OLD state);
//   FEBio's alpha_f, alpha_m are 1 - af, 1 - am.
//   Newton on x_{n+1} (free dofs), with a_{n+1} = (x_{n+1} - x_n - dt v_n)/(beta dt^2)
//   - (1/(2 beta) - 1) a_n and the consistent effective tangent
//     S = dR/dx_{n+1} = (1 - am)/(beta dt^2) M
//                       + (1 - af) (K(x_{n+1-af}) - K_ext + gamma/(beta dt) D),
//   K = d f_int/dx (Model::assemble), K_ext = d f_ext/dx (external force callback),
//   D = d f_int/dv (velocity-dependent interactions, forming/model/interaction.hpp; they
//   see t_{n+1-af} and v_{n+1-af} = (1 - af) v_{n+1} + af v_n).
//   Linear solves: TangentSolver (forming/solve/tangent_solver.hpp) for a symmetric S
//   unless the model's interactions or some external tangent are unsymmetric, then
//   (from that step on) an unsymmetric factorisation.
//   Predictor: a_{n+1} = a_n on free dofs (x_{n+1} = x_n + dt v_n + dt^2/2 a_n),
//   prescribed dofs at their positions at t_{n+1}.
//   Convergence: |R_f| <= max(residual_tol_abs, residual_tol_rel * force_scale),
//   force_scale = max(|f_int|, |f_ext|, |M a_{n+1-am}|) (2-norms over all dofs), or a
//   Newton correction below 1e-12 of the largest |x0| (round-off floor: f_int at
//   positions of size L carries round-off that drives corrections of ~10..40 eps L).
//   The iterate is the step increment x_{n+1} - x_n, so the recovered acceleration
//   a_{n+1} loses no digits to |x|; its round-off is still ~ eps L / (beta dt^2).
//
// Sign conventions: f_int = dPi_int/dx (Model::assemble) is the internal (resisting)
// force, f_ext the applied load (both in N, on the same dofs, positive along +x/+y/+z),
// so the equation of motion is M a = f_ext - f_int. Reactions on prescribed dofs are
//   r = M a_{n+1-am} + f_int(x_{n+1-af}) - f_ext,
// the force the support applies to the body (M a + f_int = f_ext + r), like
// StaticResult::reactions; e.g. a clamped cantilever under a +z tip load has sum r_z < 0.
//
// Prescribed dofs (TimedDof) follow x_d(t) = position(t) exactly at every step end;
// their velocities and accelerations come from the same Newmark relations as the free
// dofs (so a motion at constant velocity with a consistent v0_d is followed exactly,
// with v and a exact too). At the start x0_d is replaced by position(t0); v0_d is the
// caller's (give d position/dt at t0); a0_d = 0.
// Dofs no element uses (Model::used_dofs) and that are not prescribed are held at x0,
// with v = a = 0.
// Initial acceleration (free dofs f): M_ff a0_f = f_ext(t0, x0)_f - f_int(x0)_f
// (M_ff must be positive definite: every body needs a density > 0).
//
// Time stepping: dt starts at initial_dt; a failed step (too many iterations,
// divergence, inverted element at x_{n+1-af} or at the end state x_{n+1}, singular
// tangent, non-finite values) is retried from
// the last converged state with dt * cutback_factor; below min_dt the run ends with
// kStepFailed. After a step converging in <= easy_iterations Newton solves dt grows by
// `growth` (capped at max_dt). Steps are shortened to land exactly on end_time and on
// every hit time (options.hit_times, e.g. output times): the callback then sees the
// time bitwise equal to the requested value; a target between dt and 2 dt away is
// reached in two equal steps (no sliver steps). Every loop is bounded (max_steps attempts
// in total, max_iterations per step): the run ends with a report and the last converged
// state, never an endless loop. Exceptions thrown by the caller's callbacks propagate.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/solve/mass.hpp"
#include "forming/solve/step_history.hpp"

namespace sf::forming {

class TangentWorkspace;

// ---------------------------------------------------------------------------------
// Loads and prescribed motion

// External force at (time, x): force (n_dofs, N; empty = none) and, when asked for and
// the load depends on x (follower loads), its derivative d force / dx (n_dofs x n_dofs,
// N/mm; empty or without nonzeros = none).
// The same load type as the static solver's (forming/model/loads.hpp ExternalLoad), so
// the case's loads plug into both.
using ExternalForce = ExternalLoad;
// Called with the time, the positions at which the load acts (x_{n+1-af} during a step,
// x0 at the start) and whether the tangent is wanted. An empty function = no load.
// (The static solver's LoadFunction, with the time in place of the load factor.)
using ExternalForceFn = LoadFunction;

// Called once with the initial state and then after every converged step:
// time (s), positions x (mm) and velocities v (mm/s), all n_dofs.
using StepCallback = std::function<void(double time, const VecX& x, const VecX& v)>;

// ---------------------------------------------------------------------------------
// Options

enum class Integrator {
  kGeneralizedAlpha,  // Chung-Hulbert, rho_inf
  kHHTAlpha,          // Hilber-Hughes-Taylor, hht_alpha
  kNewmark,           // newmark_beta, newmark_gamma
};

// "generalized-alpha", "hht-alpha", "newmark".
std::string to_string(Integrator integrator);
// Inverse of to_string (exact, lower case); throws sf::InputError for any other name,
// the message starting with `where` when not empty and listing the accepted names.
Integrator parse_integrator(const std::string& name, const std::string& where = "");

// Derived parameters (Chung-Hulbert convention, see the header comment).
struct IntegratorParameters {
  double alpha_m = 0.0;
  double alpha_f = 0.0;
  double gamma = 0.5;
  double beta = 0.25;
};

struct DynamicOptions {
  double start_time = 0.0;        // s
  double end_time = 1.0;          // s, > start_time
  double initial_dt = 1e-3;       // s, > 0
  double min_dt = 1e-12;          // s, cut back below this -> kStepFailed; (0, initial_dt]
  double max_dt = 0.0;            // s, cap after regrowth; 0 = initial_dt; else >= initial_dt
  double growth = 1.5;            // dt growth after an easy step, >= 1
  double cutback_factor = 0.5;    // dt factor after a failed step, (0, 1)
  int easy_iterations = 4;        // ... i.e. one converging in at most this many Newton solves
  int max_iterations = 20;        // Newton solves per step
  int max_steps = 1000000;        // attempted steps in total (converged + cut back)
  std::vector<double> hit_times;  // s, steps land exactly on these (outside (start, end] ignored)

  Integrator integrator = Integrator::kGeneralizedAlpha;
  double rho_inf = 1.0;        // generalised-alpha spectral radius at dt -> inf, [0, 1]
  double hht_alpha = -0.05;    // HHT alpha, [-1/3, 0]
  double newmark_beta = 0.25;  // Newmark beta, (0, 1]; unconditionally stable if 2 beta >= gamma
  double newmark_gamma = 0.5;  // Newmark gamma, [1/2, 1]

  double residual_tol_rel = 1e-8;  // relative to force_scale
  double residual_tol_abs = 0.0;   // N
  double divergence_factor = 1e8;  // |R| growing past this times the step's first |R| fails
  bool line_search = false;        // backtracking on |R_f| (off: the mass term regularises)
  int max_line_search = 8;         // halvings of a Newton correction
  bool keep_step_records = true;   // DynamicReport::steps holds every attempted step
  linalg::SolverKind linear_solver = linalg::SolverKind::kAuto;
  // Tangent pattern and factorisation kept between solves of the same model (a run's
  // output intervals, forming/solve/tangent_solver.hpp); null: laid out for this solve.
  std::shared_ptr<TangentWorkspace> workspace;

  // Throws sf::InputError naming the option ("dynamic solver rho_inf: expected ...").
  void validate() const;
  // (am, af, gamma, beta) of the chosen integrator (validate() first).
  IntegratorParameters parameters() const;
  // max_dt with 0 resolved to initial_dt.
  double max_step() const { return max_dt > 0.0 ? max_dt : initial_dt; }
};

// ---------------------------------------------------------------------------------
// Report and result

// The time steps of a solve (forming/solve/step_history.hpp: status, message, counters,
// every attempted step with target = its end time and increment = dt, last_residual()).
struct DynamicReport : StepHistory {
  double time = 0.0;         // of the returned (last converged) state, s
  double last_dt = 0.0;      // of the last converged step, s
  double min_dt_used = 0.0;  // smallest converged step, s (0 before the first)
  double max_dt_used = 0.0;  // largest converged step, s
  // One line, e.g. "converged: t 0.001 in 100 steps (0 cut-backs), 250 Newton
  // iterations, dt 1e-05..1e-05, |R| 2e-12".
  std::string brief() const;
};

struct DynamicResult {
  VecX positions;      // last converged state x (n_dofs, mm)
  VecX velocities;     // v there (mm/s)
  VecX accelerations;  // a there (mm/s^2)
  VecX reactions;      // M a_{n+1-am} + f_int - f_ext of the last step on prescribed dofs (N), 0 elsewhere
  DynamicReport report;
};

// Integrates M a + f_int(x) = f_ext(t, x) from (options.start_time, x0, v0) to
// options.end_time. mass: n_dofs x n_dofs (mass_matrix); x0, v0: n_dofs.
DynamicResult solve_dynamic(const Model& model, const linalg::SparseMatrix& mass, const Eigen::Ref<const VecX>& x0,
                            const Eigen::Ref<const VecX>& v0, const std::vector<TimedDof>& prescribed,
                            const ExternalForceFn& external, const DynamicOptions& options = {},
                            const StepCallback& on_step = {});

}  // namespace sf::forming
