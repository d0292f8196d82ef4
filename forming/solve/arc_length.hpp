#pragma once
// Arc-length continuation (Crisfield's cylindrical arc length) for load-controlled
// problems with limit points, e.g. inflation of a membrane or tube by a follower
// pressure, whose pressure passes through a maximum.
//
// Unknowns: free positions x and the load factor lambda. Equilibrium
//   r(x, lambda) = f_int(x) - lambda q(x) = 0          on the free dofs,
// with q(x) = load(1, x).force the load at factor 1 (the load must be PROPORTIONAL:
// load(lambda, x) = lambda load(1, x); follower loads are fine), and per step the
// constraint on the increment from the last converged point,
//   |Delta x|^2 = Delta l^2                             (free dofs, mm).
// Each Newton iteration solves K dx_r = -r and K dx_q = q with K = K_int - lambda K_q
// (K_q = d q / dx), sets dx = dx_r + dlambda dx_q and takes dlambda from the quadratic
// |Delta x + dx|^2 = Delta l^2, choosing the root whose new increment makes the
// smaller angle with the step's previous increment (Crisfield). The predictor follows
// the tangent, in the direction of the previous step (the first step loads up), so
// the path runs through limit points where load control fails.
// Step size: after a step converging in few iterations Delta l grows (up to max_arc),
// a failed step is retried with half of it (down to min_arc); loops are bounded and the
// solve returns the path converged so far with a message.
//
// Prescribed dofs keep their start values. Units: mm, N.
#include <functional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/solve/step_history.hpp"

namespace sf::forming {

struct ArcLengthOptions {
  double arc_length = 0.1;         // first Delta l, mm
  double min_arc = 1e-6;           // give up below this, mm
  double max_arc = 1.0;            // mm
  int max_steps = 200;             // converged steps
  int max_attempts = 400;          // attempted steps (converged + cut back)
  int max_iterations = 20;         // Newton iterations per attempt
  int easy_iterations = 5;         // grow Delta l after a step converging in at most this many
  double residual_tol_rel = 1e-9;  // |r_f| relative to max(|f_int|, |lambda q|)
  double residual_tol_abs = 0.0;   // N
  double max_load_factor = 1e30;   // stop when lambda exceeds this
  linalg::SolverKind linear_solver = linalg::SolverKind::kAuto;
  // Throws sf::InputError naming the option.
  void validate() const;
};

struct ArcLengthPoint {
  double lambda = 0.0;
  VecX x;
  int iterations = 0;
  double residual = 0.0;  // |r_f|, N
};

// The steps of a continuation (forming/solve/step_history.hpp): one record per attempt
// (target = the load factor it ended at, increment = its arc length Delta l, the
// residual norm of its last iteration), status kConverged when it stopped as asked
// (max_load_factor, max_steps or the callback), with the message saying which.
struct ArcLengthResult : StepHistory {
  std::vector<ArcLengthPoint> path;  // converged points, the start (lambda 0) first
};

// `stop` is called after every converged point; returning true ends the solve
// (converged). The start x_start must be in equilibrium at lambda = 0.
ArcLengthResult solve_arc_length(const Model& model, const Eigen::Ref<const VecX>& x_start,
                                 const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                 bool unsymmetric, const ArcLengthOptions& options,
                                 const std::function<bool(const ArcLengthPoint&)>& stop = {});

}  // namespace sf::forming
