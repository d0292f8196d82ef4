#include "forming/solve/static_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"
#include "forming/solve/line_search.hpp"
#include "forming/solve/messages.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

[[noreturn]] void bad_option(const std::string& name, const std::string& expected, double found) {
  detail::bad_solver_option("static solver", name, expected, found);
}

// Relative size of the last Newton correction below which the state is converged even
// when the residual test is not met (round-off floor of the residual).
constexpr double kIncrementTolRel = 1e-14;

}  // namespace

// ---------------------------------------------------------------------------------
// Options and report

void StaticOptions::validate() const {
  if (!(initial_increment > 0.0 && initial_increment <= 1.0))
    bad_option("initial_increment", "a load-factor increment in (0, 1]", initial_increment);
  if (!(max_increment > 0.0 && max_increment <= 1.0))
    bad_option("max_increment", "a load-factor increment in (0, 1]", max_increment);
  if (!(min_increment > 0.0 && min_increment <= initial_increment))
    bad_option("min_increment", "a value in (0, initial_increment]", min_increment);
  if (!(growth >= 1.0) || !std::isfinite(growth)) bad_option("growth", "a finite factor >= 1", growth);
  if (easy_iterations < 1) bad_option("easy_iterations", "at least 1", easy_iterations);
  if (max_iterations < 1) bad_option("max_iterations", "at least 1", max_iterations);
  if (max_steps < 1) bad_option("max_steps", "at least 1", max_steps);
  if (!(residual_tol_rel >= 0.0)) bad_option("residual_tol_rel", "a value >= 0", residual_tol_rel);
  if (!(residual_tol_abs >= 0.0)) bad_option("residual_tol_abs", "a value >= 0 (N)", residual_tol_abs);
  if (!(divergence_factor > 1.0)) bad_option("divergence_factor", "a factor > 1", divergence_factor);
  if (max_line_search < 0) bad_option("max_line_search", "at least 0", max_line_search);
  if (!linalg::solver_available(linear_solver))
    throw InputError("static solver linear_solver: '" + linalg::to_string(linear_solver) +
                     "' is not compiled in");
}

std::string StaticReport::brief() const {
  std::ostringstream os;
  os << to_string(status) << ": lambda " << load_factor << " " << counts();
  if (n_converged_steps > 0) os << ", |r| " << detail::short_number(last_residual());
  if (!message.empty()) os << "; " << message;
  return os.str();
}

// ---------------------------------------------------------------------------------
// Newton solver

StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const VecX& f_ext,
                          const StaticOptions& options) {
  if (f_ext.size() != 0 && f_ext.size() != model.n_dofs()) {
    StaticResult result;
    result.positions = x_start;
    result.reactions = VecX::Zero(model.n_dofs());
    result.report.status = SolveStatus::kInvalidStart;
    result.report.message = "external force has " + std::to_string(f_ext.size()) + " entries, expected " +
                            std::to_string(model.n_dofs());
    return result;
  }
  const VecX dead = f_ext.size() == 0 ? VecX::Zero(model.n_dofs()) : f_ext;
  const LoadFunction load = [&dead](double lambda, const VecX&, bool) { return ExternalLoad{lambda * dead, {}}; };
  return solve_static(model, x_start, prescribed, load, false, options);
}

StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const LoadFunction& load_at,
                          bool unsymmetric, const StaticOptions& options) {
  options.validate();
  const Index n = model.n_dofs();
  StaticResult result;
  StaticReport& report = result.report;
  result.positions = x_start;
  result.reactions = VecX::Zero(n);
  auto invalid = [&](const std::string& msg) {
    report.status = SolveStatus::kInvalidStart;
    report.message = msg;
    return result;
  };
  if (x_start.size() != n)
    return invalid("start positions have " + std::to_string(x_start.size()) + " entries, expected " +
                   std::to_string(n));
  // Residual and (optionally) tangent at lambda, x: internal minus external.
  struct State {
    Assembly a;
    VecX residual;
    double scale = 0.0;  // max(|f_int|, |f_ext|)
  };
  auto evaluate = [&](double lam, const VecX& xs, bool want_tangent) {
    State st;
    st.a = model.assemble(xs, want_tangent);
    if (!st.a.ok) return st;
    ExternalLoad ext = load_at(lam, xs, want_tangent);
    SF_ASSERT(ext.force.size() == n, "external load must have n_dofs entries");
    st.residual = st.a.force - ext.force;
    st.scale = std::max(st.a.force.norm(), ext.force.norm());
    if (want_tangent && ext.tangent.size() > 0) st.a.tangent -= ext.tangent;
    return st;
  };

  // Dof classes: free, prescribed, held (used by no element).
  enum : char { kFree, kPrescribed, kHeld };
  std::vector<char> kind(n, kFree);
  VecX target = x_start;
  for (const PrescribedDof& p : prescribed) {
    if (p.dof < 0 || p.dof >= n)
      return invalid("prescribed dof " + std::to_string(p.dof) + " is outside 0.." + std::to_string(n - 1));
    if (!std::isfinite(p.value)) return invalid("prescribed dof " + std::to_string(p.dof) + " has a non-finite value");
    kind[p.dof] = kPrescribed;
    target(p.dof) = p.value;
  }
  const std::vector<bool> used = model.used_dofs();
  std::vector<bool> is_free(static_cast<std::size_t>(n), false);
  for (Index d = 0; d < n; ++d) {
    if (!used[d] && kind[d] == kFree) kind[d] = kHeld;
    is_free[static_cast<std::size_t>(d)] = kind[d] == kFree;
  }
  const FreeDofs free_dofs(is_free);
  const Index nf = free_dofs.size();
  const linalg::SparseMatrix& select = free_dofs.select;
  double length_scale = 0.0;
  for (Index d = 0; d < n; ++d) length_scale = std::max(length_scale, std::abs(x_start(d)));
  length_scale = std::max(length_scale, 1e-300);

  {
    const Assembly a0 = model.assemble(x_start, false);
    if (!a0.ok) return invalid("start state: " + a0.message);
  }

  TangentSolver solver(options.linear_solver, unsymmetric || !model.symmetric_tangent());
  VecX x = x_start;
  double lambda = 0.0;
  double increment = std::min(options.initial_increment, options.max_increment);
  auto prescribed_at = [&](double lam) {
    VecX v = x;
    for (Index d = 0; d < n; ++d)
      if (kind[d] == kPrescribed) v(d) = x_start(d) + lam * (target(d) - x_start(d));
    return v;
  };
  auto free_part = [&](const VecX& v) { return free_dofs.restrict(v); };

  int attempts = 0;
  while (lambda < 1.0) {
    if (attempts >= options.max_steps) {
      report.status = SolveStatus::kStepFailed;
      report.message = "max_steps (" + std::to_string(options.max_steps) + ") attempted load steps reached at lambda " +
                       detail::short_number(lambda);
      break;
    }
    ++attempts;
    const double lam_new = (1.0 - lambda <= increment * (1.0 + 1e-12)) ? 1.0 : lambda + increment;
    StepRecord rec;
    rec.target = lam_new;
    rec.increment = lam_new - lambda;

    // Predictor: tangent at the converged state, prescribed dofs moved.
    VecX xt = x;
    bool failed = false;
    {
      const State st = evaluate(lam_new, x, true);
      const Assembly& a = st.a;
      if (!a.ok) return invalid("converged state became inadmissible: " + a.message);
      const VecX x_new = prescribed_at(lam_new);
      const VecX dxp = x_new - x;  // nonzero on prescribed dofs only
      const VecX rhs = -free_part(st.residual + a.tangent * dxp);
      const linalg::SparseMatrix kff = select.transpose() * a.tangent * select;
      if (nf > 0) {
        const linalg::SolveReport& sr = solver.factorize(kff);
        if (!sr.ok()) {
          rec.failure = "predictor: linear solve " + sr.brief();
          failed = true;
        } else {
          const VecX dxf = solver.solve(rhs);
          xt = x_new + select * dxf;
        }
      } else {
        xt = x_new;
      }
      rec.iterations = 1;
    }
    // Corrector.
    double first_norm = -1.0;
    while (!failed) {
      const State st = evaluate(lam_new, xt, true);
      const Assembly& a = st.a;
      if (!a.ok) {
        rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + a.message;
        failed = true;
        break;
      }
      const VecX rf = free_part(st.residual);
      const double rnorm = rf.norm();
      rec.residual_norms.push_back(rnorm);
      const double scale = st.scale;
      if (first_norm < 0.0) first_norm = rnorm;
      if (rnorm <= std::max(options.residual_tol_abs, options.residual_tol_rel * scale)) {
        rec.converged = true;
        report.force_scale = scale;
        break;
      }
      if (!std::isfinite(rnorm) || rnorm > options.divergence_factor * std::max(first_norm, 1e-300)) {
        rec.failure = "diverged: |r| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) + " iterations";
        failed = true;
        break;
      }
      if (rec.iterations >= options.max_iterations) {
        rec.failure = "no convergence in " + std::to_string(options.max_iterations) + " iterations (|r| " +
                      detail::short_number(rnorm) + ", tolerance " +
                      detail::short_number(std::max(options.residual_tol_abs, options.residual_tol_rel * scale)) + ")";
        failed = true;
        break;
      }
      const linalg::SolveReport& sr = solver.factorize(select.transpose() * a.tangent * select);
      if (!sr.ok()) {
        rec.failure = "linear solve " + sr.brief();
        failed = true;
        break;
      }
      const VecX dxf = solver.solve(-rf);
      ++rec.iterations;
      if (!dxf.allFinite()) {
        rec.failure = "linear solve returned non-finite values";
        failed = true;
        break;
      }
      const VecX dx = select * dxf;
      // Round-off floor: a correction this small cannot reduce |r| further.
      if (dxf.size() == 0 || dxf.lpNorm<Eigen::Infinity>() <= kIncrementTolRel * length_scale) {
        xt += dx;
        rec.step_lengths.push_back(1.0);
        rec.converged = true;
        report.force_scale = scale;
        break;
      }
      double alpha = 1.0;
      if (options.line_search) {
        alpha = detail::backtrack(rnorm, options.max_line_search, [&](double trial_step, bool&) -> std::optional<double> {
                  const State trial = evaluate(lam_new, xt + trial_step * dx, false);
                  if (!trial.a.ok) return std::nullopt;
                  return free_part(trial.residual).norm();
                }).step;
        if (alpha < 0.0) {
          rec.failure = "iteration " + std::to_string(rec.iterations) + ": every line-search trial inverted an element";
          failed = true;
          break;
        }
      }
      xt += alpha * dx;
      rec.step_lengths.push_back(alpha);
    }
    if (rec.converged) {
      x = xt;
      lambda = lam_new;
      if (rec.iterations <= options.easy_iterations)
        increment = std::min(options.max_increment, increment * options.growth);
      report.add(std::move(rec));
      continue;
    }
    const std::string why = rec.failure;
    report.add(std::move(rec));
    increment *= 0.5;
    if (increment < options.min_increment) {
      report.status = SolveStatus::kStepFailed;
      report.message = "load step from lambda " + detail::short_number(lambda) + " failed (" + why +
                       "); increment cut back below min_increment " + detail::short_number(options.min_increment);
      break;
    }
  }
  if (lambda >= 1.0) {
    report.status = SolveStatus::kConverged;
    report.message.clear();
  }
  report.load_factor = lambda;
  result.positions = x;
  result.reactions = evaluate(lambda, x, false).residual;
  return result;
}

StaticResult solve_static_constrained(Model& model, const Eigen::Ref<const VecX>& x_start,
                                      const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                      bool unsymmetric, const StaticOptions& options, const UzawaOptions& uzawa,
                                      UzawaReport* report) {
  UzawaReport rep;
  StaticResult r = solve_static(model, x_start, prescribed, load, unsymmetric, options);
  const bool any = model.any_constrained();
  auto measure = [&](const VecX& x) {
    rep.max_g_J = rep.max_g_T = 0.0;
    for (int b = 0; b < model.n_bodies(); ++b)
      for (const Model::ConstraintState& c : model.constraint_state(b, x)) {
        if (model.constraints(b).incompressible) rep.max_g_J = std::max(rep.max_g_J, std::abs(c.g_J));
        if (model.constraints(b).inextensible) rep.max_g_T = std::max(rep.max_g_T, std::abs(c.g_T));
      }
    return std::max(rep.max_g_J, rep.max_g_T);
  };
  if (any && r.report.ok()) {
    // Every repeat starts where the last one ended, with the targets already reached:
    // its prescribed dofs do not move.
    while (measure(r.positions) > uzawa.tolerance) {
      if (rep.updates >= uzawa.max_updates) {
        rep.converged = false;
        r.report.status = SolveStatus::kStepFailed;
        r.report.message = "constraints not met after " + std::to_string(uzawa.max_updates) +
                           " multiplier updates (max |mean J - 1| " + detail::short_number(rep.max_g_J) + ", max |mean (I4 - 1)/2| " +
                           detail::short_number(rep.max_g_T) + ", tolerance " + detail::short_number(uzawa.tolerance) + ")";
        break;
      }
      for (int b = 0; b < model.n_bodies(); ++b) {
        if (!model.constrained(b)) continue;
        std::vector<double> p, t;
        for (const Model::ConstraintState& c : model.constraint_state(b, r.positions)) {
          p.push_back(c.p_eff);
          t.push_back(c.T_eff);
        }
        model.set_multipliers(b, std::move(p), std::move(t));
      }
      ++rep.updates;
      const LoadFunction full = [&load](double, const VecX& x, bool want_tangent) { return load(1.0, x, want_tangent); };
      const StaticResult again = solve_static(model, r.positions, prescribed, full, unsymmetric, options);
      const int iterations = r.report.total_iterations + again.report.total_iterations;
      r = again;
      r.report.total_iterations = iterations;
      if (!r.report.ok()) {
        rep.converged = false;
        break;
      }
    }
  }
  if (any && !r.report.ok()) rep.converged = false;
  if (report) *report = rep;
  return r;
}

}  // namespace sf::forming
