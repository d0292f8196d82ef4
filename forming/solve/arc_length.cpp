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
    if (p.dof < 0 || p.dof >= n) throw InputError("arc-length: prescribed dof " + std::to_string(p.dof) + " out of range");
    free_dof[p.dof] = false;
  }
  const FreeDofs free_dofs(free_dof);
  const Index nf = free_dofs.size();
  const linalg::SparseMatrix& select = free_dofs.select;
  auto free_part = [&](const VecX& v) { return free_dofs.restrict(v); };

  // Residual, load shape and tangent on the free dofs at (x, lambda).
  struct State {
    bool ok = false;
    std::string message;
    VecX r, q;           // free parts of f_int - lambda q and of q
    double scale = 0.0;  // max(|f_int|, |lambda q|)
    linalg::SparseMatrix k;
  };
  auto evaluate = [&](const VecX& x, double lambda, bool want_tangent) {
    State s;
    Assembly a = model.assemble(x, want_tangent);
    if (!a.ok) {
      s.message = a.message;
      return s;
    }
    const ExternalLoad shape = load(1.0, x, want_tangent);
    s.r = free_part(a.force - lambda * shape.force);
    s.q = free_part(shape.force);
    s.scale = std::max(a.force.norm(), std::abs(lambda) * shape.force.norm());
    if (want_tangent) {
      if (shape.tangent.size() > 0) a.tangent -= lambda * shape.tangent;
      s.k = select.transpose() * a.tangent * select;
    }
    s.ok = true;
    return s;
  };

  TangentSolver solver(options.linear_solver, unsymmetric || !model.symmetric_tangent());
  ArcLengthResult result;
  VecX x = x_start;
  double lambda = 0.0;
  {
    const State s0 = evaluate(x, 0.0, false);
    if (!s0.ok) throw InputError("arc-length: start state: " + s0.message);
    result.path.push_back({0.0, x, 0, s0.r.norm()});
  }
  VecX previous = VecX::Zero(nf);  // increment of the last converged step
  double arc = options.arc_length;
  int attempts = 0;
  while (static_cast<int>(result.path.size()) - 1 < options.max_steps) {
    if (attempts++ >= options.max_attempts) {
      result.message = "max_attempts reached at lambda " + detail::short_number(lambda);
      return result;
    }
    StepRecord rec;
    rec.increment = arc;
    // Predictor along the tangent.
    const State s = evaluate(x, lambda, true);
    std::string failure;
    VecX dx = VecX::Zero(nf);
    double dlambda = 0.0;
    int iterations = 0;
    double rnorm = 0.0;
    bool converged = false;
    if (!solver.factorize(s.k).ok()) {
      failure = "singular tangent at the start of the step";
    } else {
      const VecX dq = solver.solve(s.q);
      const double dir = previous.squaredNorm() > 0.0 && dq.dot(previous) < 0.0 ? -1.0 : 1.0;
      dlambda = dir * arc / std::max(dq.norm(), 1e-300);
      dx = dlambda * dq;
      for (iterations = 1; iterations <= options.max_iterations; ++iterations) {
        const VecX xt = x + select * dx;
        const State st = evaluate(xt, lambda + dlambda, true);
        if (!st.ok) {
          failure = st.message;
          break;
        }
        rnorm = st.r.norm();
        rec.residual_norms.push_back(rnorm);
        if (!std::isfinite(rnorm)) {
          failure = "non-finite residual";
          break;
        }
        if (rnorm <= std::max(options.residual_tol_abs, options.residual_tol_rel * st.scale)) {
          converged = true;
          break;
        }
        if (!solver.factorize(st.k).ok()) {
          failure = "singular tangent";
          break;
        }
        MatX rhs(nf, 2);
        rhs.col(0) = -st.r;
        rhs.col(1) = st.q;
        const MatX sol = solver.solve(rhs);
        const VecX dr = sol.col(0), dqi = sol.col(1);
        const VecX base = dx + dr;
        const double qa = dqi.squaredNorm(), qb = 2.0 * dqi.dot(base), qc = base.squaredNorm() - arc * arc;
        const double disc = qb * qb - 4.0 * qa * qc;
        if (!(qa > 0.0) || disc < 0.0) {
          failure = "the arc-length constraint has no real root";
          break;
        }
        const double root = std::sqrt(disc);
        const double l1 = (-qb + root) / (2.0 * qa), l2 = (-qb - root) / (2.0 * qa);
        const VecX c1 = base + l1 * dqi, c2 = base + l2 * dqi;
        const bool first = c1.dot(dx) >= c2.dot(dx);
        dx = first ? c1 : c2;
        dlambda += first ? l1 : l2;
      }
      if (!converged && failure.empty())
        failure = "no convergence in " + std::to_string(options.max_iterations) + " iterations (|r| " + detail::short_number(rnorm) + ")";
    }
    rec.target = lambda + dlambda;
    rec.converged = converged;
    rec.iterations = std::min(iterations, options.max_iterations);
    rec.failure = failure;
    result.add(std::move(rec));
    if (!converged) {
      arc *= 0.5;
      if (arc < options.min_arc) {
        result.message = "step from lambda " + detail::short_number(lambda) + " failed (" + failure + "); arc length below min_arc " +
                         detail::short_number(options.min_arc);
        return result;
      }
      continue;
    }
    x += select * dx;
    lambda += dlambda;
    previous = dx;
    result.path.push_back({lambda, x, iterations, rnorm});
    if (iterations <= options.easy_iterations) arc = std::min(options.max_arc, arc * 1.5);
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
