#include "forming/solve/dynamic_solver.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "forming/solve/line_search.hpp"
#include "forming/solve/messages.hpp"

namespace sf::forming {
namespace {

[[noreturn]] void bad_option(const std::string& name, const std::string& expected, double found) {
  detail::bad_solver_option("dynamic solver", name, expected, found);
}

// Relative size of a Newton correction below which the state is converged even when
// the residual test is not met (round-off floor of the residual).
// Measured: the round-off of f_int at positions of size L drives corrections of
// 10..40 eps L, so the floor is set well above that.
constexpr double kIncrementTolRel = 1e-12;
// A step within this fraction of dt of a target time lands on the target.
constexpr double kLandingTol = 1e-9;

bool has_nonzeros(const linalg::SparseMatrix& m) {
  for (int k = 0; k < m.outerSize(); ++k)
    for (linalg::SparseMatrix::InnerIterator it(m, k); it; ++it)
      if (it.value() != 0.0) return true;
  return false;
}

}  // namespace

// ---------------------------------------------------------------------------------
// Mass matrix

linalg::SparseMatrix mass_matrix(const Model& model, const std::vector<double>& density) {
  if (static_cast<int>(density.size()) != model.n_bodies())
    throw InputError("mass matrix density: expected one value per body (" + std::to_string(model.n_bodies()) +
                     "), found " + std::to_string(density.size()));
  for (int b = 0; b < model.n_bodies(); ++b)
    if (!(std::isfinite(density[b]) && density[b] >= 0.0)) {
      std::ostringstream os;
      os << "mass matrix density of body " << b << ": expected a finite value >= 0 (t/mm^3), found "
         << density[b];
      throw InputError(os.str());
    }
  const quadrature::TensorRule<3> rule = model.rule().brick();
  std::vector<basis::BrickValues> values;
  values.reserve(rule.size());
  for (int q = 0; q < rule.size(); ++q)
    values.push_back(basis::BicubicHermiteLinear::evaluate(rule.points[q], basis::kValues | basis::kFirst));

  const Index n = model.n_dofs();
  linalg::TripletAssembler triplets(n, n);
  Index n_el = 0;
  for (int b = 0; b < model.n_bodies(); ++b) n_el += model.ply(b).n_elements();
  triplets.reserve(n_el * 3 * kBrickFunctions * kBrickFunctions);
  std::vector<Index> dofs;
  std::vector<double> coefs;
  std::vector<int> local;
  MatX block;
  for (int b = 0; b < model.n_bodies(); ++b) {
    const PlyMesh& ply = model.ply(b);
    const double rho = density[b];
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickParams X_e = ply.element_parameters(e, ply.reference());
      Eigen::Matrix<double, kBrickFunctions, kBrickFunctions> m_e =
          Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>::Zero();
      for (int q = 0; q < rule.size(); ++q) {
        const Mat3 G = X_e.transpose() * values[q].first;  // G(i, a) = dX_i / dxi_a
        const double det_g = G.determinant();
        if (!(det_g > 0.0))
          throw InputError("mass matrix: body " + std::to_string(b) + " element " + std::to_string(e) +
                           " has an inverted reference geometry (det G " + detail::short_number(det_g) + " at a Gauss point)");
        m_e.noalias() += (rho * rule.weights[q] * det_g) * (values[q].value * values[q].value.transpose());
      }
      const BrickMap map = ply.element_map(e);
      for (int i = 0; i < 3; ++i) {
        dofs.clear();
        coefs.clear();
        local.clear();
        for (int k = 0; k < kBrickFunctions; ++k)
          for (int t = 0; t < map.n_terms[k]; ++t) {
            dofs.push_back(model.offset(b) + 3 * map.terms[k][t].dof + i);
            coefs.push_back(map.terms[k][t].coef);
            local.push_back(k);
          }
        const int m = static_cast<int>(dofs.size());
        block.resize(m, m);
        for (int c = 0; c < m; ++c)
          for (int a = 0; a < m; ++a) block(a, c) = coefs[a] * coefs[c] * m_e(local[a], local[c]);
        triplets.add_block(dofs, dofs, block);
      }
    }
  }
  return triplets.compress();
}

double kinetic_energy(const linalg::SparseMatrix& mass, const Eigen::Ref<const VecX>& velocity) {
  const VecX mv = mass * velocity;
  return 0.5 * velocity.dot(mv);
}

// ---------------------------------------------------------------------------------
// Options and report

std::string to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::kGeneralizedAlpha:
      return "generalized-alpha";
    case Integrator::kHHTAlpha:
      return "hht-alpha";
    case Integrator::kNewmark:
      return "newmark";
  }
  return "unknown";
}

Integrator parse_integrator(const std::string& name, const std::string& where) {
  for (Integrator i : {Integrator::kGeneralizedAlpha, Integrator::kHHTAlpha, Integrator::kNewmark})
    if (name == to_string(i)) return i;
  std::string msg = where.empty() ? std::string() : where + ": ";
  msg += "unknown integrator '" + name + "' (expected generalized-alpha, hht-alpha or newmark)";
  throw InputError(msg);
}

void DynamicOptions::validate() const {
  if (!std::isfinite(start_time)) bad_option("start_time", "a finite time (s)", start_time);
  if (!(std::isfinite(end_time) && end_time > start_time))
    bad_option("end_time", "a finite time > start_time (s)", end_time);
  if (!(std::isfinite(initial_dt) && initial_dt > 0.0)) bad_option("initial_dt", "a finite time step > 0 (s)", initial_dt);
  if (!(min_dt > 0.0 && min_dt <= initial_dt)) bad_option("min_dt", "a time step in (0, initial_dt] (s)", min_dt);
  if (!(std::isfinite(max_dt) && (max_dt == 0.0 || max_dt >= initial_dt)))
    bad_option("max_dt", "0 (= initial_dt) or a finite time step >= initial_dt (s)", max_dt);
  if (!(growth >= 1.0 && std::isfinite(growth))) bad_option("growth", "a finite factor >= 1", growth);
  if (!(cutback_factor > 0.0 && cutback_factor < 1.0)) bad_option("cutback_factor", "a factor in (0, 1)", cutback_factor);
  if (easy_iterations < 1) bad_option("easy_iterations", "at least 1", easy_iterations);
  if (max_iterations < 1) bad_option("max_iterations", "at least 1", max_iterations);
  if (max_steps < 1) bad_option("max_steps", "at least 1", max_steps);
  for (double h : hit_times)
    if (!std::isfinite(h)) bad_option("hit_times", "finite times (s)", h);
  switch (integrator) {
    case Integrator::kGeneralizedAlpha:
      if (!(rho_inf >= 0.0 && rho_inf <= 1.0)) bad_option("rho_inf", "a spectral radius in [0, 1]", rho_inf);
      break;
    case Integrator::kHHTAlpha:
      if (!(hht_alpha >= -1.0 / 3.0 && hht_alpha <= 0.0)) bad_option("hht_alpha", "a value in [-1/3, 0]", hht_alpha);
      break;
    case Integrator::kNewmark:
      if (!(newmark_gamma >= 0.5 && newmark_gamma <= 1.0)) bad_option("newmark_gamma", "a value in [1/2, 1]", newmark_gamma);
      if (!(newmark_beta > 0.0 && newmark_beta <= 1.0)) bad_option("newmark_beta", "a value in (0, 1]", newmark_beta);
      break;
  }
  if (!(residual_tol_rel >= 0.0)) bad_option("residual_tol_rel", "a value >= 0", residual_tol_rel);
  if (!(residual_tol_abs >= 0.0)) bad_option("residual_tol_abs", "a value >= 0 (N)", residual_tol_abs);
  if (!(residual_tol_rel > 0.0 || residual_tol_abs > 0.0))
    bad_option("residual_tol_rel", "a value > 0 when residual_tol_abs is 0", residual_tol_rel);
  if (!(divergence_factor > 1.0)) bad_option("divergence_factor", "a factor > 1", divergence_factor);
  if (max_line_search < 0) bad_option("max_line_search", "at least 0", max_line_search);
  if (!linalg::solver_available(linear_solver))
    throw InputError("dynamic solver linear_solver: '" + linalg::to_string(linear_solver) + "' is not compiled in");
}

IntegratorParameters DynamicOptions::parameters() const {
  IntegratorParameters p;
  switch (integrator) {
    case Integrator::kGeneralizedAlpha:
      p.alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
      p.alpha_f = rho_inf / (rho_inf + 1.0);
      break;
    case Integrator::kHHTAlpha:
      p.alpha_m = 0.0;
      p.alpha_f = -hht_alpha;
      break;
    case Integrator::kNewmark:
      p.alpha_m = 0.0;
      p.alpha_f = 0.0;
      p.gamma = newmark_gamma;
      p.beta = newmark_beta;
      return p;
  }
  p.gamma = 0.5 - p.alpha_m + p.alpha_f;
  p.beta = 0.25 * (1.0 - p.alpha_m + p.alpha_f) * (1.0 - p.alpha_m + p.alpha_f);
  return p;
}

std::string to_string(DynamicReport::Status status) {
  switch (status) {
    case DynamicReport::Status::kCompleted:
      return "completed";
    case DynamicReport::Status::kStepFailed:
      return "step-failed";
    case DynamicReport::Status::kInvalidStart:
      return "invalid-start";
  }
  return "unknown";
}

std::string DynamicReport::brief() const {
  std::ostringstream os;
  os << to_string(status) << ": t " << time << " in " << n_converged_steps << " steps (" << n_cutbacks
     << " cut-backs), " << total_iterations << " Newton iterations";
  if (n_converged_steps > 0) os << ", dt " << detail::short_number(min_dt_used) << ".." << detail::short_number(max_dt_used);
  for (auto it = steps.rbegin(); it != steps.rend(); ++it)
    if (it->converged && !it->residual_norms.empty()) {
      os << ", |R| " << detail::short_number(it->residual_norms.back());
      break;
    }
  if (!message.empty()) os << "; " << message;
  return os.str();
}

// ---------------------------------------------------------------------------------
// Time integration

DynamicResult solve_dynamic(const Model& model, const linalg::SparseMatrix& mass,
                            const Eigen::Ref<const VecX>& x0, const Eigen::Ref<const VecX>& v0,
                            const std::vector<TimedDof>& prescribed, const ExternalForceFn& external,
                            const DynamicOptions& options, const StepCallback& on_step) {
  options.validate();
  const IntegratorParameters ip = options.parameters();
  const double am = ip.alpha_m, af = ip.alpha_f, beta = ip.beta, gamma = ip.gamma;
  const Index n = model.n_dofs();

  DynamicResult result;
  DynamicReport& report = result.report;
  result.positions = x0;
  result.velocities = v0;
  result.accelerations = VecX::Zero(x0.size());
  result.reactions = VecX::Zero(x0.size());
  report.time = options.start_time;
  auto invalid = [&](const std::string& msg) {
    report.status = DynamicReport::Status::kInvalidStart;
    report.message = msg;
    return result;
  };
  if (x0.size() != n)
    return invalid("start positions have " + std::to_string(x0.size()) + " entries, expected " + std::to_string(n));
  if (v0.size() != n)
    return invalid("start velocities have " + std::to_string(v0.size()) + " entries, expected " + std::to_string(n));
  if (mass.rows() != n || mass.cols() != n)
    return invalid("mass matrix is " + std::to_string(mass.rows()) + " x " + std::to_string(mass.cols()) +
                   ", expected " + std::to_string(n) + " x " + std::to_string(n));
  if (!x0.allFinite() || !v0.allFinite()) return invalid("start positions or velocities are not finite");

  // Dof classes: free, prescribed, held (used by no element, not prescribed).
  enum : char { kFree, kPrescribed, kHeld };
  std::vector<char> kind(n, kFree);
  for (const TimedDof& p : prescribed) {
    if (p.dof < 0 || p.dof >= n)
      return invalid("prescribed dof " + std::to_string(p.dof) + " is outside 0.." + std::to_string(n - 1));
    if (!p.position) return invalid("prescribed dof " + std::to_string(p.dof) + " has no position function");
    if (kind[p.dof] == kPrescribed) return invalid("dof " + std::to_string(p.dof) + " is prescribed twice");
    kind[p.dof] = kPrescribed;
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
  auto free_part = [&](const VecX& v) { return free_dofs.restrict(v); };
  // Sets the prescribed dofs of y to their positions at time t; false (and a message)
  // when a position is not finite.
  auto set_prescribed = [&](double t, VecX& y, std::string& why) {
    for (const TimedDof& p : prescribed) {
      const double value = p.position(t);
      if (!std::isfinite(value)) {
        why = "prescribed dof " + std::to_string(p.dof) + " has a non-finite position at t = " + detail::short_number(t);
        return false;
      }
      y(p.dof) = value;
    }
    return true;
  };
  // External force at (t, x); false (and a message) on a wrong size.
  auto eval_external = [&](double t, const VecX& x, bool want_tangent, ExternalForce& out, std::string& why) {
    if (external) {
      out = external(t, x, want_tangent);
    } else {
      out = ExternalForce{};
    }
    if (out.force.size() == 0) out.force = VecX::Zero(n);
    if (out.force.size() != n) {
      why = "external force has " + std::to_string(out.force.size()) + " entries, expected " + std::to_string(n);
      return false;
    }
    if (!out.force.allFinite()) {
      why = "external force is not finite at t = " + detail::short_number(t);
      return false;
    }
    if (out.tangent.nonZeros() > 0 && (out.tangent.rows() != n || out.tangent.cols() != n)) {
      why = "external tangent is " + std::to_string(out.tangent.rows()) + " x " + std::to_string(out.tangent.cols()) +
            ", expected " + std::to_string(n) + " x " + std::to_string(n);
      return false;
    }
    return true;
  };

  double t = options.start_time;
  VecX x = x0;
  VecX v = v0;
  VecX a = VecX::Zero(n);
  {
    std::string why;
    if (!set_prescribed(t, x, why)) return invalid(why);
  }
  for (Index d = 0; d < n; ++d)
    if (kind[d] == kHeld) v(d) = 0.0;
  double length_scale = 1e-300;
  for (Index d = 0; d < n; ++d) length_scale = std::max(length_scale, std::abs(x(d)));

  // Initial acceleration: M_ff a_f = f_ext_f - f_int_f (a = 0 on prescribed and held dofs).
  {
    const Assembly a0 = model.assemble(x, false);
    if (!a0.ok) return invalid("start state: " + a0.message);
    ExternalForce ext;
    std::string why;
    if (!eval_external(t, x, false, ext, why)) return invalid("start state: " + why);
    if (nf > 0) {
      linalg::LinearSolver msolver(options.linear_solver, linalg::MatrixProperty::kSymmetricPositiveDefinite);
      const linalg::SparseMatrix mff = select.transpose() * mass * select;
      const linalg::SolveReport& sr = msolver.factorize(mff);
      if (!sr.ok())
        return invalid("mass matrix on the free dofs cannot be factorised (a body without density?): " + sr.brief());
      const VecX rhs = free_part(ext.force - a0.force);
      const VecX af0 = msolver.solve(rhs);
      if (!af0.allFinite()) return invalid("initial acceleration is not finite");
      a = select * af0;
    }
  }
  result.positions = x;
  result.velocities = v;
  result.accelerations = a;
  if (on_step) on_step(t, x, v);

  // Effective-tangent solver: symmetric until an external tangent has nonzeros.
  std::unique_ptr<TangentSolver> solver = std::make_unique<TangentSolver>(options.linear_solver, false);
  bool unsymmetric = false;

  std::vector<double> hits;
  for (double h : options.hit_times)
    if (h > options.start_time && h < options.end_time) hits.push_back(h);
  std::sort(hits.begin(), hits.end());
  std::size_t next_hit = 0;

  const double max_dt = options.max_step();
  double dt = std::min(options.initial_dt, max_dt);
  int attempts = 0;
  bool fatal = false;
  while (t < options.end_time) {
    if (attempts >= options.max_steps) {
      report.status = DynamicReport::Status::kStepFailed;
      report.message = "max_steps (" + std::to_string(options.max_steps) + ") attempted time steps reached at t = " + detail::short_number(t);
      break;
    }
    ++attempts;
    while (next_hit < hits.size() && hits[next_hit] <= t) ++next_hit;
    const double target = next_hit < hits.size() ? hits[next_hit] : options.end_time;
    // Land on the target when it is within dt; between dt and 2 dt away take half the
    // remaining interval (no sliver step: a_{n+1} ~ 1/dt^2 amplifies round-off).
    const double remaining = target - t;
    const double t_new = remaining <= dt * (1.0 + kLandingTol) ? target
                         : remaining < 2.0 * dt               ? t + 0.5 * remaining
                                                              : t + dt;
    const double h = t_new - t;
    DynamicStepRecord rec;
    rec.time = t_new;
    rec.dt = h;

    // Newmark relations in the step increment y = x_{n+1} - x_n (iterated instead of
    // x_{n+1} itself so that a_{n+1} = c0 (y - base) does not lose digits to |x|):
    //   base = dt v_n + dt^2 (1/2 - beta) a_n.
    const double c0 = 1.0 / (beta * h * h);
    const double t_alpha = (1.0 - af) * t_new + af * t;
    const VecX base = h * v + (h * h * (0.5 - beta)) * a;
    VecX y = h * v + (0.5 * h * h) * a;  // predictor a_{n+1} = a_n
    bool failed = false;
    {
      VecX x_new = x;
      if (!set_prescribed(t_new, x_new, rec.failure)) {
        failed = true;
        fatal = true;
      }
      for (const TimedDof& p : prescribed) y(p.dof) = x_new(p.dof) - x(p.dof);
    }
    // Residual R (all dofs) at y; false on an inverted element or a bad external force.
    struct Eval {
      VecX residual;
      linalg::SparseMatrix tangent;
      double scale = 0.0;
    };
    auto evaluate = [&](const VecX& yy, bool want_tangent, Eval& ev, std::string& why) {
      const VecX a1 = c0 * (yy - base);
      const VecX xa = x + (1.0 - af) * yy;
      const VecX aa = (1.0 - am) * a1 + am * a;
      const Assembly asm_ = model.assemble(xa, want_tangent);
      if (!asm_.ok) {
        why = asm_.message;
        return false;
      }
      ExternalForce ext;
      if (!eval_external(t_alpha, xa, want_tangent, ext, why)) {
        fatal = true;
        return false;
      }
      const VecX inertia = mass * aa;
      ev.residual = inertia + asm_.force - ext.force;
      ev.scale = std::max({asm_.force.norm(), ext.force.norm(), inertia.norm()});
      if (!ev.residual.allFinite()) {
        why = "non-finite residual";
        return false;
      }
      if (want_tangent) {
        ev.tangent = (c0 * (1.0 - am)) * mass + (1.0 - af) * asm_.tangent;
        if (has_nonzeros(ext.tangent)) {
          ev.tangent -= (1.0 - af) * ext.tangent;
          if (!unsymmetric) {
            try {
              solver = std::make_unique<TangentSolver>(options.linear_solver, true);
            } catch (const InputError& e) {
              why = std::string("the external load has an unsymmetric tangent: ") + e.what();
              fatal = true;
              return false;
            }
            unsymmetric = true;
          }
        }
      }
      return true;
    };

    Eval ev;
    double first_norm = -1.0;
    while (!failed) {
      std::string why;
      if (!evaluate(y, true, ev, why)) {
        rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + why;
        failed = true;
        break;
      }
      const VecX rf = free_part(ev.residual);
      const double rnorm = rf.norm();
      rec.residual_norms.push_back(rnorm);
      if (first_norm < 0.0) first_norm = rnorm;
      const double tol = std::max(options.residual_tol_abs, options.residual_tol_rel * ev.scale);
      if (rnorm <= tol) {
        rec.converged = true;
        break;
      }
      if (rnorm > options.divergence_factor * std::max(first_norm, 1e-300)) {
        rec.failure = "diverged: |R| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) + " iterations";
        failed = true;
        break;
      }
      if (rec.iterations >= options.max_iterations) {
        rec.failure = "no convergence in " + std::to_string(options.max_iterations) + " iterations (|R| " +
                      detail::short_number(rnorm) + ", tolerance " + detail::short_number(tol) + ")";
        failed = true;
        break;
      }
      const linalg::SolveReport& sr = solver->factorize(select.transpose() * ev.tangent * select);
      if (!sr.ok()) {
        rec.failure = "linear solve " + sr.brief();
        failed = true;
        break;
      }
      const VecX dyf = solver->solve(-rf);
      ++rec.iterations;
      if (!dyf.allFinite()) {
        rec.failure = "linear solve returned non-finite values";
        failed = true;
        break;
      }
      const VecX dy = select * dyf;
      if (dyf.lpNorm<Eigen::Infinity>() <= kIncrementTolRel * length_scale) {
        y += dy;
        rec.step_lengths.push_back(1.0);
        // Final state: residual (for the reactions) without the tangent.
        if (!evaluate(y, false, ev, why)) {
          rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + why;
          failed = true;
          break;
        }
        rec.residual_norms.push_back(free_part(ev.residual).norm());
        rec.converged = true;
        break;
      }
      double step = 1.0;
      if (options.line_search) {
        const detail::LineSearch ls =
            detail::backtrack(rnorm, options.max_line_search, [&](double trial_step, bool& stop) -> std::optional<double> {
              Eval trial;
              std::string trial_why;
              if (!evaluate(y + trial_step * dy, false, trial, trial_why)) {
                stop = fatal;
                return std::nullopt;
              }
              return free_part(trial.residual).norm();
            });
        if (ls.stopped) {
          rec.failure = "iteration " + std::to_string(rec.iterations) + ": external force failed";
          failed = true;
          break;
        }
        if (ls.step < 0.0) {
          rec.failure = "iteration " + std::to_string(rec.iterations) + ": every line-search trial inverted an element";
          failed = true;
          break;
        }
        step = ls.step;
      }
      y += step * dy;
      rec.step_lengths.push_back(step);
    }

    // The end state must be admissible too (with af > 0 only x_{n+1-af} was assembled).
    if (rec.converged && af > 0.0) {
      const VecX x_end = x + y;
      const Assembly end = model.assemble(x_end, false);
      if (!end.ok) {
        rec.converged = false;
        rec.failure = "end state: " + end.message;
      }
    }
    report.total_iterations += rec.iterations;
    if (rec.converged) {
      const VecX a_new = c0 * (y - base);
      v += h * ((1.0 - gamma) * a + gamma * a_new);
      a = a_new;
      x += y;
      set_prescribed(t_new, x, rec.failure);  // exact prescribed values (no round-off drift)
      t = t_new;
      ++report.n_converged_steps;
      report.last_dt = h;
      report.min_dt_used = report.n_converged_steps == 1 ? h : std::min(report.min_dt_used, h);
      report.max_dt_used = std::max(report.max_dt_used, h);
      for (Index d = 0; d < n; ++d) result.reactions(d) = kind[d] == kPrescribed ? ev.residual(d) : 0.0;
      if (rec.iterations <= options.easy_iterations) dt = std::min(max_dt, dt * options.growth);
      if (options.keep_step_records) report.steps.push_back(std::move(rec));
      if (on_step) on_step(t, x, v);
      continue;
    }
    ++report.n_cutbacks;
    const std::string why = rec.failure;
    if (options.keep_step_records) report.steps.push_back(std::move(rec));
    if (fatal) {
      report.status = DynamicReport::Status::kStepFailed;
      report.message = "time step from t = " + detail::short_number(t) + " failed: " + why;
      break;
    }
    dt = std::min(dt, h) * options.cutback_factor;
    if (dt < options.min_dt) {
      report.status = DynamicReport::Status::kStepFailed;
      report.message = "time step from t = " + detail::short_number(t) + " failed (" + why + "); dt cut back below min_dt " +
                       detail::short_number(options.min_dt);
      break;
    }
  }
  if (t >= options.end_time) {
    report.status = DynamicReport::Status::kCompleted;
    report.message.clear();
  }
  report.time = t;
  result.positions = x;
  result.velocities = v;
  result.accelerations = a;
  return result;
}

}  // namespace sf::forming
