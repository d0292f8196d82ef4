#include "forming/solve/arc_length.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"
#include "forming/solve/messages.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

[[noreturn]] void bad_option(const std::string& name, const std::string& expected, double found) {
  detail::bad_solver_option("arc-length", name, expected, found);
}

}  // namespace

void ArcLengthOptions::validate() const {
  if (!(arc_length > 0.0) || !std::isfinite(arc_length)) bad_option("arc_length", "a length > 0 (mm)", arc_length);
  if (!(min_arc > 0.0 && min_arc <= arc_length)) bad_option("min_arc", "a length in (0, arc_length]", min_arc);
  if (!(max_arc >= arc_length) || !std::isfinite(max_arc)) bad_option("max_arc", "a length >= arc_length", max_arc);
  if (max_steps < 1) bad_option("max_steps", "at least 1", max_steps);
  if (max_attempts < max_steps) bad_option("max_attempts", "at least max_steps", max_attempts);
  if (max_iterations < 1) bad_option("max_iterations", "at least 1", max_iterations);
  if (easy_iterations < 1) bad_option("easy_iterations", "at least 1", easy_iterations);
  if (!(residual_tol_rel >= 0.0)) bad_option("residual_tol_rel", "a value >= 0", residual_tol_rel);
  if (!(residual_tol_abs >= 0.0)) bad_option("residual_tol_abs", "a value >= 0 (N)", residual_tol_abs);
  if (!(residual_tol_rel > 0.0 || residual_tol_abs > 0.0))
    bad_option("residual_tol_rel", "a positive tolerance (relative or absolute)", residual_tol_rel);
}

namespace {

// Residual, load shape and tangent on the free dofs at (x, lambda).
struct ArcState {
  bool ok = false;
  std::string message;
  VecX r, q;           // free parts of f_int - lambda q and of q
  double scale = 0.0;  // max(|f_int|, |lambda q|)
  // With the tangent: K_ff - lambda (dq/dx)_ff is in the continuation's pattern until
  // the next evaluation.
};

// An attempted step: the increment from the last converged point and how it went.
struct ArcStep {
  VecX dx;  // free dofs, mm
  double dlambda = 0.0;
  int iterations = 0;  // residual evaluations after the predictor (the last one converged)
  double rnorm = 0.0;  // |r_f| of the last one, N
  bool converged = false;
  std::string failure;
};

// The equations of one continuation and the Newton iteration of a step.
class Continuation {
 public:
  Continuation(const Model& model, const LoadFunction& load, bool unsymmetric, const ArcLengthOptions& options,
               const std::vector<bool>& is_free)
      : model_(model),
        load_(load),
        options_(options),
        free_(is_free),
        solver_(options.linear_solver, unsymmetric || !model.symmetric_tangent()),
        pattern_(model.make_pattern(is_free, solver_.lower())) {
    // The tangent is assembled in the Cholesky's order and factorised in place (no copy).
    solver_.lay_out(pattern_);
  }
  Continuation(const Continuation&) = delete;  // solver_ holds a pointer to pattern_
  Continuation& operator=(const Continuation&) = delete;

  Index n_free() const { return free_.size(); }
  const FreeDofs& free() const { return free_; }
  ArcState evaluate(const VecX& x, double lambda, bool want_tangent);
  // A step of length `arc` from (x, lambda): predictor along the tangent (in the
  // direction of the previous increment), then Newton on (dx, dlambda) with the
  // constraint |dx| = arc.
  ArcStep attempt(const VecX& x, double lambda, const VecX& previous, double arc);

 private:
  // Corrects (dx, dlambda) once; false (step.failure) when the step cannot go on.
  bool correct(const ArcState& st, double arc, ArcStep& step);

  const Model& model_;
  const LoadFunction& load_;
  const ArcLengthOptions& options_;
  FreeDofs free_;
  TangentSolver solver_;
  linalg::PatternAssembler pattern_;
};

ArcState Continuation::evaluate(const VecX& x, double lambda, bool want_tangent) {
  ArcState s;
  Assembly a = model_.assemble_into(x, InteractionContext{}, want_tangent ? &pattern_ : nullptr);
  if (!a.ok) {
    s.message = a.message;
    return s;
  }
  const ExternalLoad shape = load_(1.0, x, want_tangent);
  s.r = free_.restrict(a.force - lambda * shape.force);
  s.q = free_.restrict(shape.force);
  s.scale = std::max(a.force.norm(), std::abs(lambda) * shape.force.norm());
  if (want_tangent && shape.tangent.size() > 0) {
    pattern_.add(shape.tangent, -lambda);
    pattern_.flush();
  }
  s.ok = true;
  return s;
}

ArcStep Continuation::attempt(const VecX& x, double lambda, const VecX& previous, double arc) {
  ArcStep step;
  step.dx = VecX::Zero(n_free());
  const ArcState s = evaluate(x, lambda, true);
  if (!s.ok) {
    step.failure = s.message;
    return step;
  }
  if (!solver_.factorize(pattern_.matrix()).ok()) {
    step.failure = "singular tangent at the start of the step";
    return step;
  }
  const VecX dq = solver_.solve(s.q);
  const double dir = previous.squaredNorm() > 0.0 && dq.dot(previous) < 0.0 ? -1.0 : 1.0;
  step.dlambda = dir * arc / std::max(dq.norm(), 1e-300);
  step.dx = step.dlambda * dq;
  for (step.iterations = 1; step.iterations <= options_.max_iterations; ++step.iterations) {
    const VecX xt = x + free_.expand(step.dx);
    const ArcState st = evaluate(xt, lambda + step.dlambda, true);
    if (!st.ok) {
      step.failure = st.message;
      return step;
    }
    step.rnorm = st.r.norm();
    if (!std::isfinite(step.rnorm)) {
      step.failure = "non-finite residual";
      return step;
    }
    if (step.rnorm <= std::max(options_.residual_tol_abs, options_.residual_tol_rel * st.scale)) {
      step.converged = true;
      return step;
    }
    if (!correct(st, arc, step)) return step;
  }
  step.failure = "no convergence in " + std::to_string(options_.max_iterations) + " iterations (|r| " +
                 detail::short_number(step.rnorm) + ")";
  return step;
}

// K dx_r = -r and K dx_q = q; dx = dx + dx_r + dl dx_q with dl from |dx|^2 = arc^2, the
// root whose increment makes the smaller angle with the current one.
bool Continuation::correct(const ArcState& st, double arc, ArcStep& step) {
  if (!solver_.factorize(pattern_.matrix()).ok()) {
    step.failure = "singular tangent";
    return false;
  }
  MatX rhs(n_free(), 2);
  rhs.col(0) = -st.r;
  rhs.col(1) = st.q;
  const MatX sol = solver_.solve(rhs);
  const VecX dr = sol.col(0), dqi = sol.col(1);
  const VecX base = step.dx + dr;
  const double qa = dqi.squaredNorm(), qb = 2.0 * dqi.dot(base), qc = base.squaredNorm() - arc * arc;
  const double disc = qb * qb - 4.0 * qa * qc;
  if (!(qa > 0.0) || disc < 0.0) {
    step.failure = "the arc-length constraint has no real root";
    return false;
  }
  const double root = std::sqrt(disc);
  const double l1 = (-qb + root) / (2.0 * qa), l2 = (-qb - root) / (2.0 * qa);
  const VecX c1 = base + l1 * dqi, c2 = base + l2 * dqi;
  const bool first = c1.dot(step.dx) >= c2.dot(step.dx);
  step.dx = first ? c1 : c2;
  step.dlambda += first ? l1 : l2;
  return true;
}

}  // namespace

ArcLengthResult solve_arc_length(const Model& model, const Eigen::Ref<const VecX>& x_start,
                                 const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                 bool unsymmetric, const ArcLengthOptions& options,
                                 const std::function<bool(const ArcLengthPoint&)>& stop) {
  options.validate();
  const Index n = model.n_dofs();
  if (x_start.size() != n)
    throw InputError("arc-length: start positions have " + std::to_string(x_start.size()) + " entries, expected " +
                     std::to_string(n));
  std::vector<bool> free_dof = model.used_dofs();
  for (const PrescribedDof& p : prescribed) {
    if (p.dof < 0 || p.dof >= n)
      throw InputError("arc-length: prescribed dof " + std::to_string(p.dof) + " out of range");
    free_dof[p.dof] = false;
  }
  Continuation path(model, load, unsymmetric, options, free_dof);
  ArcLengthResult result;
  VecX x = x_start;
  double lambda = 0.0;
  {
    const ArcState s0 = path.evaluate(x, 0.0, false);
    if (!s0.ok) throw InputError("arc-length: start state: " + s0.message);
    result.path.push_back({0.0, x, 0, s0.r.norm()});
  }
  VecX previous = VecX::Zero(path.n_free());  // increment of the last converged step
  double arc = options.arc_length;
  int attempts = 0;
  while (static_cast<int>(result.path.size()) - 1 < options.max_steps) {
    if (attempts++ >= options.max_attempts) {
      result.message = "max_attempts reached at lambda " + detail::short_number(lambda);
      return result;
    }
    const ArcStep step = path.attempt(x, lambda, previous, arc);
    StepRecord rec;
    rec.target = lambda + step.dlambda;
    rec.increment = arc;
    rec.converged = step.converged;
    rec.iterations = std::min(step.iterations, options.max_iterations);
    if (step.iterations > 0) rec.residual_norms.push_back(step.rnorm);
    rec.failure = step.failure;
    result.add(std::move(rec));
    if (!step.converged) {
      arc *= 0.5;
      if (arc < options.min_arc) {
        result.message = "step from lambda " + detail::short_number(lambda) + " failed (" + step.failure +
                         "); arc length below min_arc " + detail::short_number(options.min_arc);
        return result;
      }
      continue;
    }
    x += path.free().expand(step.dx);
    lambda += step.dlambda;
    previous = step.dx;
    result.path.push_back({lambda, x, step.iterations, step.rnorm});
    if (step.iterations <= options.easy_iterations) arc = std::min(options.max_arc, arc * 1.5);
    if (lambda > options.max_load_factor) {
      result.status = SolveStatus::kConverged;
      result.message = "load factor " + detail::short_number(lambda) + " passed max_load_factor";
      return result;
    }
    if (stop && stop(result.path.back())) {
      result.status = SolveStatus::kConverged;
      result.message = "stopped by the caller at lambda " + detail::short_number(lambda);
      return result;
    }
  }
  result.status = SolveStatus::kConverged;
  result.message = "max_steps reached at lambda " + detail::short_number(lambda);
  return result;
}

}  // namespace sf::forming
