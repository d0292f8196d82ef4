#include "forming/solve/dynamic_solver.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
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
  if (!(std::isfinite(initial_dt) && initial_dt > 0.0))
    bad_option("initial_dt", "a finite time step > 0 (s)", initial_dt);
  if (!(min_dt > 0.0 && min_dt <= initial_dt)) bad_option("min_dt", "a time step in (0, initial_dt] (s)", min_dt);
  if (!(std::isfinite(max_dt) && (max_dt == 0.0 || max_dt >= initial_dt)))
    bad_option("max_dt", "0 (= initial_dt) or a finite time step >= initial_dt (s)", max_dt);
  if (!(growth >= 1.0 && std::isfinite(growth))) bad_option("growth", "a finite factor >= 1", growth);
  if (!(cutback_factor > 0.0 && cutback_factor < 1.0))
    bad_option("cutback_factor", "a factor in (0, 1)", cutback_factor);
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
      if (!(newmark_gamma >= 0.5 && newmark_gamma <= 1.0))
        bad_option("newmark_gamma", "a value in [1/2, 1]", newmark_gamma);
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

std::string DynamicReport::brief() const {
  std::ostringstream os;
  os << to_string(status) << ": t " << time << " " << counts();
  if (n_converged_steps > 0) {
    os << ", dt " << detail::short_number(min_dt_used) << ".." << detail::short_number(max_dt_used);
    os << ", |R| " << detail::short_number(last_residual());
  }
  if (!message.empty()) os << "; " << message;
  return os.str();
}

// ---------------------------------------------------------------------------------
// Time integration

namespace {

// Where the next step ends: steps land exactly on the hit times and on end_time; a
// target between dt and 2 dt away is reached in two equal steps (no sliver step:
// a_{n+1} ~ 1/dt^2 amplifies round-off). dt grows after easy steps and is cut back
// after failed ones.
class StepClock {
 public:
  explicit StepClock(const DynamicOptions& options) : options_(options), max_dt_(options.max_step()) {
    for (double h : options.hit_times)
      if (h > options.start_time && h < options.end_time) hits_.push_back(h);
    std::sort(hits_.begin(), hits_.end());
    dt_ = std::min(options.initial_dt, max_dt_);
  }

  double next_end(double t) {
    while (next_hit_ < hits_.size() && hits_[next_hit_] <= t) ++next_hit_;
    const double target = next_hit_ < hits_.size() ? hits_[next_hit_] : options_.end_time;
    const double remaining = target - t;
    return remaining <= dt_ * (1.0 + kLandingTol) ? target : remaining < 2.0 * dt_ ? t + 0.5 * remaining : t + dt_;
  }
  void grow() { dt_ = std::min(max_dt_, dt_ * options_.growth); }
  // After a failed step of length h; false when dt falls below min_dt.
  bool cut_back(double h) {
    dt_ = std::min(dt_, h) * options_.cutback_factor;
    return dt_ >= options_.min_dt;
  }

 private:
  const DynamicOptions& options_;
  double max_dt_;
  double dt_ = 0.0;
  std::vector<double> hits_;
  std::size_t next_hit_ = 0;
};

// One time step from t_n to t_new = t_n + h and its Newton iterate: the Newmark
// relations are written in the step increment y = x_{n+1} - x_n (iterated instead of
// x_{n+1} itself so that a_{n+1} = c0 (y - base) does not lose digits to |x|).
struct TimeStep {
  double h = 0.0;        // s
  double t_new = 0.0;    // t_{n+1}, s
  double t_alpha = 0.0;  // t_{n+1-af}, s
  double c0 = 0.0;       // 1 / (beta h^2)
  VecX base;             // h v_n + h^2 (1/2 - beta) a_n
  VecX y;                // the iterate (predictor: a_{n+1} = a_n)
};

// Residual R (all dofs) at an iterate, the effective tangent S and the force scale.
// (S itself is in the integration's pattern, until the next balance with the tangent.)
struct Balance {
  VecX residual;
  double scale = 0.0;
};

// The state (t, x, v, a) of a generalised-alpha integration and the pieces of a step:
// start, the balance at an iterate, Newton on a step, and acceptance.
class TimeIntegration {
 public:
  TimeIntegration(const Model& model, const linalg::SparseMatrix& mass, const std::vector<TimedDof>& prescribed,
                  const ExternalForceFn& external, const DynamicOptions& options)
      : model_(model), mass_(mass), prescribed_(prescribed), external_(external), options_(options) {
    const IntegratorParameters ip = options.parameters();
    am_ = ip.alpha_m;
    af_ = ip.alpha_f;
    beta_ = ip.beta;
    gamma_ = ip.gamma;
    for (int i = 0; i < model.n_interactions(); ++i)
      velocity_dependent_ = velocity_dependent_ || model.interaction(i).needs_velocity();
  }

  // Checks the inputs, classifies the dofs and sets the start state: prescribed dofs at
  // their positions at start_time, held dofs at rest, the initial acceleration
  // M_ff a_f = f_ext_f - f_int_f. Returns why the start is invalid (empty when valid).
  std::string start(const Eigen::Ref<const VecX>& x0, const Eigen::Ref<const VecX>& v0);
  // Attempts the step to t_new from the current state; the record says whether it
  // converged (then `step.y` is the increment and `end` the balance there) and why not.
  StepRecord attempt(double t_new, TimeStep& step, Balance& end);
  // Moves the state to the end of a converged step; reactions on the prescribed dofs.
  void accept(const TimeStep& step, const Balance& end, VecX& reactions);

  bool fatal() const { return fatal_; }  // a failure no smaller step can fix
  double time() const { return t_; }
  const VecX& x() const { return x_; }
  const VecX& v() const { return v_; }
  const VecX& a() const { return a_; }

 private:
  enum : char { kFree, kPrescribed, kHeld };
  std::string classify_dofs();
  std::string initial_acceleration();
  bool set_prescribed(double t, VecX& y, std::string& why) const;
  bool external_force(double t, const VecX& x, bool want_tangent, ExternalForce& out, std::string& why) const;
  bool balance(const TimeStep& s, const VecX& y, bool want_tangent, Balance& out, std::string& why);
  void newton(TimeStep& s, Balance& end, StepRecord& rec);
  // Line-search factor along dy; < 0 (and rec.failure) when no trial could be evaluated.
  double line_search(const TimeStep& s, const VecX& dy, double rnorm, StepRecord& rec);

  const Model& model_;
  const linalg::SparseMatrix& mass_;
  const std::vector<TimedDof>& prescribed_;
  const ExternalForceFn& external_;
  const DynamicOptions& options_;
  double am_ = 0.0, af_ = 0.0, beta_ = 0.25, gamma_ = 0.5;
  bool velocity_dependent_ = false;  // some interaction's force depends on v

  std::vector<char> kind_;
  FreeDofs free_;
  double length_scale_ = 1e-300;
  std::shared_ptr<TangentWorkspace> workspace_;  // pattern and solver (kept between solves when shared)
  TangentSolver* solver_ = nullptr;
  linalg::PatternAssembler* pattern_ = nullptr;  // S_ff, laid out for solver_
  std::vector<std::int64_t> mass_pos_;           // positions of M's entries in pattern_
  int mass_generation_ = -1;                     // pattern_ generation mass_pos_ is for
  bool unsymmetric_ = false;
  bool fatal_ = false;

  double t_ = 0.0;
  VecX x_, v_, a_;
};

std::string TimeIntegration::start(const Eigen::Ref<const VecX>& x0, const Eigen::Ref<const VecX>& v0) {
  const Index n = model_.n_dofs();
  if (x0.size() != n)
    return "start positions have " + std::to_string(x0.size()) + " entries, expected " + std::to_string(n);
  if (v0.size() != n)
    return "start velocities have " + std::to_string(v0.size()) + " entries, expected " + std::to_string(n);
  if (mass_.rows() != n || mass_.cols() != n)
    return "mass matrix is " + std::to_string(mass_.rows()) + " x " + std::to_string(mass_.cols()) + ", expected " +
           std::to_string(n) + " x " + std::to_string(n);
  if (!x0.allFinite() || !v0.allFinite()) return "start positions or velocities are not finite";
  if (std::string why = classify_dofs(); !why.empty()) return why;

  t_ = options_.start_time;
  x_ = x0;
  v_ = v0;
  a_ = VecX::Zero(n);
  if (std::string why; !set_prescribed(t_, x_, why)) return why;
  for (Index d = 0; d < n; ++d)
    if (kind_[d] == kHeld) v_(d) = 0.0;
  for (Index d = 0; d < n; ++d) length_scale_ = std::max(length_scale_, std::abs(x_(d)));
  if (std::string why = initial_acceleration(); !why.empty()) return why;

  // Effective-tangent solver: symmetric until an unsymmetric tangent shows up.
  // (kept unsymmetric when an earlier solve of this model found an unsymmetric tangent).
  workspace_ = options_.workspace ? options_.workspace : std::make_shared<TangentWorkspace>();
  unsymmetric_ = !model_.symmetric_tangent() || workspace_->unsymmetric_for(model_);
  workspace_->prepare(model_, free_.is_free, options_.linear_solver, unsymmetric_);
  solver_ = &workspace_->solver();
  pattern_ = &workspace_->pattern();
  return {};
}

// Free, prescribed, held (used by no element, not prescribed).
std::string TimeIntegration::classify_dofs() {
  const Index n = model_.n_dofs();
  kind_.assign(static_cast<std::size_t>(n), kFree);
  for (const TimedDof& p : prescribed_) {
    if (p.dof < 0 || p.dof >= n)
      return "prescribed dof " + std::to_string(p.dof) + " is outside 0.." + std::to_string(n - 1);
    if (!p.position) return "prescribed dof " + std::to_string(p.dof) + " has no position function";
    if (kind_[p.dof] == kPrescribed) return "dof " + std::to_string(p.dof) + " is prescribed twice";
    kind_[p.dof] = kPrescribed;
  }
  const std::vector<bool> used = model_.used_dofs();
  std::vector<bool> is_free(static_cast<std::size_t>(n), false);
  for (Index d = 0; d < n; ++d) {
    if (!used[d] && kind_[d] == kFree) kind_[d] = kHeld;
    is_free[static_cast<std::size_t>(d)] = kind_[d] == kFree;
  }
  free_ = FreeDofs(is_free);
  return {};
}

// M_ff a_f = f_ext_f - f_int_f (a = 0 on prescribed and held dofs).
std::string TimeIntegration::initial_acceleration() {
  const InteractionContext context{t_, velocity_dependent_ ? &v_ : nullptr};
  const Assembly a0 = model_.assemble(x_, context, false);
  if (!a0.ok) return "start state: " + a0.message;
  ExternalForce ext;
  std::string why;
  if (!external_force(t_, x_, false, ext, why)) return "start state: " + why;
  if (free_.size() == 0) return {};
  linalg::LinearSolver msolver(options_.linear_solver, linalg::MatrixProperty::kSymmetricPositiveDefinite);
  const linalg::SparseMatrix mff = free_.select.transpose() * mass_ * free_.select;
  const linalg::SolveReport& sr = msolver.factorize(mff);
  if (!sr.ok()) return "mass matrix on the free dofs cannot be factorised (a body without density?): " + sr.brief();
  const VecX rhs = free_.restrict(ext.force - a0.force);
  const VecX af0 = msolver.solve(rhs);
  if (!af0.allFinite()) return "initial acceleration is not finite";
  a_ = free_.select * af0;
  return {};
}

// Sets the prescribed dofs of y to their positions at time t; false (and why) when a
// position is not finite.
bool TimeIntegration::set_prescribed(double t, VecX& y, std::string& why) const {
  for (const TimedDof& p : prescribed_) {
    const double value = p.position(t);
    if (!std::isfinite(value)) {
      why = "prescribed dof " + std::to_string(p.dof) + " has a non-finite position at t = " + detail::short_number(t);
      return false;
    }
    y(p.dof) = value;
  }
  return true;
}

// External force at (t, x); false (and why) on a wrong size or non-finite values.
bool TimeIntegration::external_force(double t, const VecX& x, bool want_tangent, ExternalForce& out,
                                     std::string& why) const {
  const Index n = model_.n_dofs();
  out = external_ ? external_(t, x, want_tangent) : ExternalForce{};
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
}

// R = M a_{n+1-am} + f(x_{n+1-af}, v_{n+1-af}) - f_ext(t_{n+1-af}, x_{n+1-af}) at the
// iterate y, and (want_tangent) S = dR/dy. False (and why) on an inverted element or a
// bad external force (the latter is fatal).
bool TimeIntegration::balance(const TimeStep& s, const VecX& y, bool want_tangent, Balance& out, std::string& why) {
  const VecX a1 = s.c0 * (y - s.base);
  const VecX xa = x_ + (1.0 - af_) * y;
  const VecX aa = (1.0 - am_) * a1 + am_ * a_;
  InteractionContext context{s.t_alpha, nullptr};
  VecX va;
  if (velocity_dependent_) {
    va = v_ + ((1.0 - af_) * s.h) * ((1.0 - gamma_) * a_ + gamma_ * a1);
    context.velocity = &va;
  }
  const Assembly internal = model_.assemble_into(xa, context, want_tangent ? pattern_ : nullptr);
  if (!internal.ok) {
    why = internal.message;
    return false;
  }
  ExternalForce ext;
  if (!external_force(s.t_alpha, xa, want_tangent, ext, why)) {
    fatal_ = true;
    return false;
  }
  const VecX inertia = mass_ * aa;
  out.residual = inertia + internal.force - ext.force;
  out.scale = std::max({internal.force.norm(), internal.element_force_norm, ext.force.norm(), inertia.norm()});
  if (!out.residual.allFinite()) {
    why = "non-finite residual";
    return false;
  }
  if (!want_tangent) return true;
  if (has_nonzeros(ext.tangent) && !unsymmetric_) {
    // The first unsymmetric tangent: both triangles and an unsymmetric solver from now on.
    try {
      workspace_->make_unsymmetric(model_);
    } catch (const InputError& e) {
      why = std::string("the external load has an unsymmetric tangent: ") + e.what();
      fatal_ = true;
      return false;
    }
    unsymmetric_ = true;
    solver_ = &workspace_->solver();
    pattern_ = &workspace_->pattern();
    mass_generation_ = -1;
    return balance(s, y, want_tangent, out, why);
  }
  // S = (1 - af) K + c0 (1 - am) M + (1 - af) gamma h c0 D - (1 - af) dF_ext/dx on the free dofs.
  linalg::SparseMatrix& S = pattern_->matrix();
  S.coeffs() *= (1.0 - af_);
  if (mass_generation_ != pattern_->generation()) {
    mass_pos_ = pattern_->positions_of(mass_);
    mass_generation_ = pattern_->generation();
  }
  const double cm = s.c0 * (1.0 - am_);
  std::size_t t = 0;
  for (int k = 0; k < mass_.outerSize(); ++k)
    for (linalg::SparseMatrix::InnerIterator it(mass_, k); it; ++it, ++t) {
      if (mass_pos_[t] >= 0)
        S.valuePtr()[mass_pos_[t]] += cm * it.value();
      else
        pattern_->add(it.row(), it.col(), cm * it.value());  // dropped, or outside the pattern
    }
  if (internal.damping.size() > 0) pattern_->add(internal.damping, (1.0 - af_) * gamma_ * s.h * s.c0);
  if (has_nonzeros(ext.tangent)) pattern_->add(ext.tangent, -(1.0 - af_));
  if (pattern_->flush()) mass_generation_ = -1;
  return true;
}

StepRecord TimeIntegration::attempt(double t_new, TimeStep& s, Balance& end) {
  s.t_new = t_new;
  s.h = t_new - t_;
  s.c0 = 1.0 / (beta_ * s.h * s.h);
  s.t_alpha = (1.0 - af_) * t_new + af_ * t_;
  s.base = s.h * v_ + (s.h * s.h * (0.5 - beta_)) * a_;
  s.y = s.h * v_ + (0.5 * s.h * s.h) * a_;  // predictor a_{n+1} = a_n
  StepRecord rec;
  rec.target = t_new;
  rec.increment = s.h;
  VecX x_new = x_;
  const bool moved = set_prescribed(t_new, x_new, rec.failure);
  for (const TimedDof& p : prescribed_) s.y(p.dof) = x_new(p.dof) - x_(p.dof);
  if (!moved) {
    fatal_ = true;
    return rec;
  }
  newton(s, end, rec);
  // The end state must be admissible too (with af > 0 only x_{n+1-af} was assembled).
  if (rec.converged && af_ > 0.0) {
    const VecX x_end = x_ + s.y;
    const Assembly a_end = model_.assemble(x_end, false);
    if (!a_end.ok) {
      rec.converged = false;
      rec.failure = "end state: " + a_end.message;
    }
  }
  return rec;
}

// Newton on the step increment until |R_f| meets the tolerance or a correction reaches
// the round-off floor; the record gets every residual norm and line-search factor.
void TimeIntegration::newton(TimeStep& s, Balance& end, StepRecord& rec) {
  double first_norm = -1.0;
  for (;;) {
    std::string why;
    if (!balance(s, s.y, true, end, why)) {
      rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + why;
      return;
    }
    const VecX rf = free_.restrict(end.residual);
    const double rnorm = rf.norm();
    rec.residual_norms.push_back(rnorm);
    if (first_norm < 0.0) first_norm = rnorm;
    const double tol = std::max(options_.residual_tol_abs, options_.residual_tol_rel * end.scale);
    if (rnorm <= tol) {
      rec.converged = true;
      return;
    }
    if (rnorm > options_.divergence_factor * std::max(first_norm, 1e-300)) {
      rec.failure =
          "diverged: |R| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) + " iterations";
      return;
    }
    if (rec.iterations >= options_.max_iterations) {
      rec.failure = "no convergence in " + std::to_string(options_.max_iterations) + " iterations (|R| " +
                    detail::short_number(rnorm) + ", tolerance " + detail::short_number(tol) + ")";
      return;
    }
    const linalg::SolveReport& sr = solver_->factorize(pattern_->matrix());
    if (!sr.ok()) {
      rec.failure = "linear solve " + sr.brief();
      return;
    }
    const VecX dyf = solver_->solve(-rf);
    ++rec.iterations;
    if (!dyf.allFinite()) {
      rec.failure = "linear solve returned non-finite values";
      return;
    }
    const VecX dy = free_.expand(dyf);
    if (dyf.lpNorm<Eigen::Infinity>() <= kIncrementTolRel * length_scale_) {
      s.y += dy;
      rec.step_lengths.push_back(1.0);
      // Final state: residual (for the reactions) without the tangent.
      if (!balance(s, s.y, false, end, why)) {
        rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + why;
        return;
      }
      rec.residual_norms.push_back(free_.restrict(end.residual).norm());
      rec.converged = true;
      return;
    }
    const double step = options_.line_search ? line_search(s, dy, rnorm, rec) : 1.0;
    if (step < 0.0) return;
    s.y += step * dy;
    rec.step_lengths.push_back(step);
  }
}

double TimeIntegration::line_search(const TimeStep& s, const VecX& dy, double rnorm, StepRecord& rec) {
  const detail::LineSearch ls =
      detail::backtrack(rnorm, options_.max_line_search, [&](double trial_step, bool& stop) -> std::optional<double> {
        Balance trial;
        std::string trial_why;
        if (!balance(s, s.y + trial_step * dy, false, trial, trial_why)) {
          stop = fatal_;
          return std::nullopt;
        }
        return free_.restrict(trial.residual).norm();
      });
  if (ls.stopped) {
    rec.failure = "iteration " + std::to_string(rec.iterations) + ": external force failed";
    return -1.0;
  }
  if (ls.step < 0.0) {
    rec.failure = "iteration " + std::to_string(rec.iterations) + ": every line-search trial inverted an element";
    return -1.0;
  }
  return ls.step;
}

void TimeIntegration::accept(const TimeStep& s, const Balance& end, VecX& reactions) {
  const VecX a_new = s.c0 * (s.y - s.base);
  v_ += s.h * ((1.0 - gamma_) * a_ + gamma_ * a_new);
  a_ = a_new;
  x_ += s.y;
  std::string unused;
  set_prescribed(s.t_new, x_, unused);  // exact prescribed values (no round-off drift; finite: checked in attempt)
  t_ = s.t_new;
  for (Index d = 0; d < model_.n_dofs(); ++d) reactions(d) = kind_[d] == kPrescribed ? end.residual(d) : 0.0;
}

}  // namespace

DynamicResult solve_dynamic(const Model& model, const linalg::SparseMatrix& mass, const Eigen::Ref<const VecX>& x0,
                            const Eigen::Ref<const VecX>& v0, const std::vector<TimedDof>& prescribed,
                            const ExternalForceFn& external, const DynamicOptions& options,
                            const StepCallback& on_step) {
  options.validate();
  DynamicResult result;
  DynamicReport& report = result.report;
  result.positions = x0;
  result.velocities = v0;
  result.accelerations = VecX::Zero(x0.size());
  result.reactions = VecX::Zero(x0.size());
  report.time = options.start_time;

  TimeIntegration run(model, mass, prescribed, external, options);
  if (const std::string why = run.start(x0, v0); !why.empty()) {
    report.status = SolveStatus::kInvalidStart;
    report.message = why;
    return result;
  }
  if (on_step) on_step(run.time(), run.x(), run.v());

  StepClock clock(options);
  int attempts = 0;
  while (run.time() < options.end_time) {
    if (attempts >= options.max_steps) {
      report.status = SolveStatus::kStepFailed;
      report.message = "max_steps (" + std::to_string(options.max_steps) +
                       ") attempted time steps reached at t = " + detail::short_number(run.time());
      break;
    }
    ++attempts;
    TimeStep step;
    Balance end;
    StepRecord rec = run.attempt(clock.next_end(run.time()), step, end);
    if (rec.converged) {
      run.accept(step, end, result.reactions);
      report.last_dt = step.h;
      report.min_dt_used = report.n_converged_steps == 0 ? step.h : std::min(report.min_dt_used, step.h);
      report.max_dt_used = std::max(report.max_dt_used, step.h);
      if (rec.iterations <= options.easy_iterations) clock.grow();
      report.add(std::move(rec), options.keep_step_records);
      if (on_step) on_step(run.time(), run.x(), run.v());
      continue;
    }
    const std::string why = rec.failure;
    report.add(std::move(rec), options.keep_step_records);
    const std::string from = "time step from t = " + detail::short_number(run.time());
    if (run.fatal()) {
      report.status = SolveStatus::kStepFailed;
      report.message = from + " failed: " + why;
      break;
    }
    if (!clock.cut_back(step.h)) {
      report.status = SolveStatus::kStepFailed;
      report.message = from + " failed (" + why + "); dt cut back below min_dt " + detail::short_number(options.min_dt);
      break;
    }
  }
  if (run.time() >= options.end_time) {
    report.status = SolveStatus::kConverged;
    report.message.clear();
  }
  report.time = run.time();
  result.positions = run.x();
  result.velocities = run.v();
  result.accelerations = run.a();
  return result;
}

}  // namespace sf::forming
