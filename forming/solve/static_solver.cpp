#include "forming/solve/static_solver.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"
#include "forming/solve/branch_switch.hpp"
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
// A load step whose last kStallWindow corrections were all damped by the line search
// and reduced |r_f| by less than half, after at least kStallAfter iterations, is cut back.
constexpr int kStallAfter = 8;
constexpr std::size_t kStallWindow = 5;
// Watchdog of the corrector (LoadStepping::correct).
constexpr double kBounce = 100.0;
constexpr int kWatch = 3;

// The trace line of a tangent: its factorisation, negative pivots (symmetric LDL^T), the
// sign of its determinant (MUMPS) and the nearest eigenvalue (forming/solve/branch_switch.hpp)
// with where its mode is largest.
void trace_tangent(const char* what, TangentSolver& solver, const linalg::SparseMatrix& k,
                   const linalg::SolveReport& sr, const Model& model, const FreeDofs& free, const VecX& x) {
  double spread = 1.0;
  VecX mode;
  const double lambda = nearest_eigenvalue(solver, k, spread, mode);
  std::fprintf(stderr, "newton:   %s: %s, negative pivots %d, det sign %+d, nearest eigenvalue %.3e max|K_ii| "
               "(spread %.1e)\n", what, sr.brief().c_str(), sr.negative_pivots, sr.determinant_sign, lambda, spread);
  if (mode.size() == free.size() && mode.size() > 0)
    std::fprintf(stderr, "newton:     its mode: %s\n", describe(mode_place(model, free.expand(mode), x)).c_str());
}

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
  if (regrow_after < 0) bad_option("regrow_after", "at least 0", regrow_after);
  if (max_iterations < 1) bad_option("max_iterations", "at least 1", max_iterations);
  if (max_steps < 1) bad_option("max_steps", "at least 1", max_steps);
  if (give_up_after < 0) bad_option("give_up_after", "at least 0 (0: off)", give_up_after);
  if (!(residual_tol_rel >= 0.0)) bad_option("residual_tol_rel", "a value >= 0", residual_tol_rel);
  if (!(residual_tol_abs >= 0.0)) bad_option("residual_tol_abs", "a value >= 0 (N)", residual_tol_abs);
  if (!(divergence_factor > 1.0)) bad_option("divergence_factor", "a factor > 1", divergence_factor);
  if (max_line_search < 0) bad_option("max_line_search", "at least 0", max_line_search);
  if (!(std::isfinite(clock.start) && std::isfinite(clock.end) && clock.end >= clock.start))
    throw InputError("static solver clock: expected finite times with end >= start (s)");
  if (!linalg::solver_available(linear_solver))
    throw InputError("static solver linear_solver: '" + linalg::to_string(linear_solver) + "' is not compiled in");
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
    result.report.message =
        "external force has " + std::to_string(f_ext.size()) + " entries, expected " + std::to_string(model.n_dofs());
    return result;
  }
  const VecX dead = f_ext.size() == 0 ? VecX::Zero(model.n_dofs()) : f_ext;
  const LoadFunction load = [&dead](double lambda, const VecX&, bool) { return ExternalLoad{lambda * dead, {}}; };
  return solve_static(model, x_start, prescribed, load, false, options);
}

namespace {

// Residual and (optionally) tangent at (lambda, x): internal minus external.
struct Residual {
  Assembly a;
  VecX residual;
  double scale = 0.0;  // max(|f_int|, |f_elements|, |f_ext|)
};

// The load steps of one static solve: the dof classes, the tangent solver, and the
// predictor and corrector of a step. solve_static() drives them.
class LoadStepping {
 public:
  LoadStepping(const Model& model, const Eigen::Ref<const VecX>& x_start, const LoadFunction& load, bool unsymmetric,
               const StaticOptions& options)
      : model_(model),
        x_start_(x_start),
        load_(load),
        options_(options),
        unsymmetric_(unsymmetric || !model.symmetric_tangent()),
        workspace_(options.workspace ? options.workspace : std::make_shared<TangentWorkspace>()),
        rates_from_(options.clock.previous ? *options.clock.previous : VecX(x_start)),
        rates_time_(options.clock.previous ? options.clock.previous_time : options.clock.start) {
    last_rates_from_ = rates_from_;
    last_rates_time_ = rates_time_;
  }

  // Free, prescribed (with their targets at lambda = 1) and held (used by no element)
  // dofs; returns why the input is invalid (empty when valid).
  std::string classify(const std::vector<PrescribedDof>& prescribed);
  // Residual at (lambda, x); with want_tangent also K_ff - (load tangent)_ff in pattern_,
  // and with `direction` K direction (all dofs) in a.tangent_times.
  Residual evaluate(double lambda, const VecX& x, bool want_tangent, const VecX* direction = nullptr);
  // A sub-step converged at (lambda, x): the interactions' rates start from it when the
  // clock runs (options.clock); the reactions keep the rates of that sub-step.
  void converged(double lambda, const VecX& x);
  // Residual at the last converged state with the rates of its own sub-step (reactions);
  // residual only (no pattern).
  Residual final_residual(double lambda, const VecX& x);

  enum class Predicted { kOk, kFailed, kInadmissible };
  // Predictor from the converged state x to lam_new: tangent at x, prescribed dofs
  // moved; the first iterate in xt (kFailed: rec.failure says why; kInadmissible: the
  // converged state no longer assembles, `why`).
  Predicted predict(double lam_new, const VecX& x, VecX& xt, StepRecord& rec, std::string& why);
  // Corrector: Newton from xt until converged (rec.converged, force_scale set) or
  // failed (rec.failure).
  void correct(double lam_new, VecX& xt, StepRecord& rec, double& force_scale);

 private:
  enum : char { kFree, kPrescribed, kHeld };
  VecX prescribed_at(double lambda, const VecX& x) const;
  // Line-search factor along dx; < 0 (rec.failure) when every trial inverted an element.
  // `at_step` receives the residual norm and force scale at the accepted step.
  // dxf, rf: the correction and the residual on the free dofs (the slope dxf . r_f).
  double line_search(double lam_new, const VecX& xt, const VecX& dx, const VecX& dxf, const VecX& rf, double rnorm,
                     double scale, StepRecord& rec, std::pair<double, double>& at_step, bool allow_bounce = false,
                     bool* bounced = nullptr);

  Residual evaluate_with(double lambda, const VecX& x, bool want_tangent, const VecX* direction, const VecX& from,
                         double from_time);

  const Model& model_;
  const Eigen::Ref<const VecX>& x_start_;
  const LoadFunction& load_;
  const StaticOptions& options_;
  bool unsymmetric_ = false;
  std::shared_ptr<TangentWorkspace> workspace_;  // pattern and solver (kept between solves when shared)
  TangentSolver* solver_ = nullptr;
  VecX rates_from_, last_rates_from_;  // where the interactions' rates start (clock)
  double rates_time_ = 0.0, last_rates_time_ = 0.0;
  std::vector<char> kind_;
  VecX target_;
  FreeDofs free_;
  linalg::PatternAssembler* pattern_ = nullptr;  // K_ff, in workspace_
  double length_scale_ = 0.0;
};

std::string LoadStepping::classify(const std::vector<PrescribedDof>& prescribed) {
  const Index n = model_.n_dofs();
  kind_.assign(static_cast<std::size_t>(n), kFree);
  target_ = x_start_;
  for (const PrescribedDof& p : prescribed) {
    if (p.dof < 0 || p.dof >= n)
      return "prescribed dof " + std::to_string(p.dof) + " is outside 0.." + std::to_string(n - 1);
    if (!std::isfinite(p.value)) return "prescribed dof " + std::to_string(p.dof) + " has a non-finite value";
    kind_[p.dof] = kPrescribed;
    target_(p.dof) = p.value;
  }
  const std::vector<bool> used = model_.used_dofs();
  std::vector<bool> is_free(static_cast<std::size_t>(n), false);
  for (Index d = 0; d < n; ++d) {
    if (!used[d] && kind_[d] == kFree) kind_[d] = kHeld;
    is_free[static_cast<std::size_t>(d)] = kind_[d] == kFree;
  }
  free_ = FreeDofs(is_free);
  workspace_->prepare(model_, is_free, options_.linear_solver, unsymmetric_);
  solver_ = &workspace_->solver();
  pattern_ = &workspace_->pattern();
  for (Index d = 0; d < n; ++d) length_scale_ = std::max(length_scale_, std::abs(x_start_(d)));
  length_scale_ = std::max(length_scale_, 1e-300);
  return {};
}

Residual LoadStepping::evaluate(double lambda, const VecX& x, bool want_tangent, const VecX* direction) {
  return evaluate_with(lambda, x, want_tangent, direction, rates_from_, rates_time_);
}

Residual LoadStepping::final_residual(double lambda, const VecX& x) {
  return evaluate_with(lambda, x, false, nullptr, last_rates_from_, last_rates_time_);
}

void LoadStepping::converged(double lambda, const VecX& x) {
  if (!(options_.clock.end > options_.clock.start)) return;  // the time stands still
  if (options_.on_substep) options_.on_substep(rates_from_, rates_time_, x, options_.clock.at(lambda));
  last_rates_from_ = rates_from_;
  last_rates_time_ = rates_time_;
  rates_from_ = x;
  rates_time_ = options_.clock.at(lambda);
}

Residual LoadStepping::evaluate_with(double lambda, const VecX& x, bool want_tangent, const VecX* direction,
                                     const VecX& from, double from_time) {
  Residual st;
  const InteractionContext context{options_.clock.at(lambda), nullptr, &from, from_time};
  st.a = model_.assemble_into(x, context, want_tangent ? pattern_ : nullptr, direction);
  if (!st.a.ok) return st;
  ExternalLoad ext = load_(lambda, x, want_tangent || direction != nullptr);
  SF_ASSERT(ext.force.size() == model_.n_dofs(), "external load must have n_dofs entries");
  st.residual = st.a.force - ext.force;
  st.scale = std::max({st.a.force.norm(), st.a.element_force_norm, ext.force.norm()});
  if (ext.tangent.size() > 0) {
    if (want_tangent) {
      pattern_->add(ext.tangent, -1.0);
      pattern_->flush();
    }
    if (direction) st.a.tangent_times -= ext.tangent * (*direction);
  }
  return st;
}

// x with the prescribed dofs moved to their values at lambda (linear from the start).
VecX LoadStepping::prescribed_at(double lambda, const VecX& x) const {
  VecX v = x;
  for (Index d = 0; d < model_.n_dofs(); ++d)
    if (kind_[d] == kPrescribed) v(d) = x_start_(d) + lambda * (target_(d) - x_start_(d));
  return v;
}

LoadStepping::Predicted LoadStepping::predict(double lam_new, const VecX& x, VecX& xt, StepRecord& rec,
                                              std::string& why) {
  xt = x;
  rec.iterations = 1;
  const VecX x_new = prescribed_at(lam_new, x);
  const VecX dxp = x_new - x;  // nonzero on prescribed dofs only
  const Residual st = evaluate(lam_new, x, true, &dxp);
  const Assembly& a = st.a;
  if (!a.ok) {
    why = "converged state became inadmissible: " + a.message;
    return Predicted::kInadmissible;
  }
  if (free_.size() == 0) {
    xt = x_new;
    return Predicted::kOk;
  }
  // Linearised response to the load and prescribed-displacement increment:
  // K_ff dx_f = -(r_f(lambda_new, x) + K_fp dx_p).
  const VecX rhs = -free_.restrict(st.residual + a.tangent_times);
  const linalg::SolveReport& sr = solver_->factorize(pattern_->matrix());
  if (!sr.ok()) {
    rec.failure = "predictor: linear solve " + sr.brief();
    return Predicted::kFailed;
  }
  static const bool trace_tangents = std::getenv("SF_NEWTON_TRACE") != nullptr;
  // The tangent at the converged state (before the tools move): its determinant's sign
  // changing between steps means an odd number of real eigenvalues passed zero.
  if (trace_tangents) trace_tangent("predictor tangent", *solver_, pattern_->matrix(), sr, model_, free_, x);
  const VecX dxf = solver_->solve(rhs);
  const VecX dx = free_.expand(dxf);
  xt = x_new + dx;
  // The predictor is a Newton step from x_new (the tools and prescribed dofs already at
  // their new places) and is damped like the corrector's steps: linearised at the old
  // state, with a tool a whole increment into a ply, the full step can overshoot far
  // (a ply of near-inextensible fibres pushed into a curve it cannot take without
  // stretch: |r| 1e3 N against forces of a few N in the matched-die bend).
  if (options_.line_search && dxf.allFinite()) {
    std::pair<double, double> at_step{0.0, 0.0};
    const double alpha = line_search(lam_new, x_new, dx, dxf, -rhs, rhs.norm(), st.scale, rec, at_step);
    if (alpha < 0.0) return Predicted::kFailed;
    xt = x_new + alpha * dx;
    static const bool trace = std::getenv("SF_NEWTON_TRACE") != nullptr;
    if (trace) std::fprintf(stderr, "newton: lambda %.6g predictor |r| %.3e step %.3g\n", lam_new, rhs.norm(), alpha);
  }
  return Predicted::kOk;
}

void LoadStepping::correct(double lam_new, VecX& xt, StepRecord& rec, double& force_scale) {
  double first_norm = -1.0;
  // Residual at xt: the first one assembled here, later ones from the line search's
  // accepted trial, so a converged state costs no tangent.
  double rnorm = 0.0, scale = 0.0;
  {
    const Residual st = evaluate(lam_new, xt, false);
    if (!st.a.ok) {
      rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + st.a.message;
      return;
    }
    rnorm = free_.restrict(st.residual).norm();
    scale = st.scale;
  }
  // SF_NEWTON_TRACE=1 in the environment: one line per Newton iteration on stderr (the
  // residual, its tolerance and the line-search step), to see how a step converges.
  static const bool trace = std::getenv("SF_NEWTON_TRACE") != nullptr;
  // Watchdog (Chamberlain et al. 1982, options_.watchdog): a full step the line search
  // would damp is taken when |r_f| rises by at most kBounce; within kWatch iterations
  // (full steps on the same terms) |r_f| must fall below its value before that step,
  // else Newton goes back to that state and damps as before, without a watchdog for the
  // rest of the load step. Why: where the residual is strongly nonlinear on a scale of
  // micrometres (a contact layer's 0.5 um taper, the second-order stretch of fibres
  // 25000 times stiffer than the matrix), the first full step raises |r_f| 10-75 times
  // and the next ones converge, while damping by |r_f| crawls with steps of 0.01
  // (the pull-out sample: 111 iterations and a cut-back, 73 and none with it).
  VecX x_ref;
  double r_ref = 0.0, scale_ref = 0.0;
  int since = -1;
  bool may_bounce = options_.watchdog;
  for (;;) {
    if (since >= 0) {
      ++since;
      if (rnorm <= (1.0 - detail::kSufficientDecrease) * r_ref) {
        since = -1;
      } else if (since >= kWatch || !(rnorm <= kBounce * r_ref)) {
        if (trace) std::fprintf(stderr, "newton:   watchdog: back to |r| %.3e\n", r_ref);
        xt = x_ref;
        rnorm = r_ref;
        scale = scale_ref;
        since = -1;
        may_bounce = false;
      }
    }
    rec.residual_norms.push_back(rnorm);
    if (first_norm < 0.0) first_norm = rnorm;
    const double tol = std::max(options_.residual_tol_abs, options_.residual_tol_rel * scale);
    if (trace)
      std::fprintf(stderr, "newton: lambda %.6g iteration %d |r| %.3e tol %.3e step %.3g\n", lam_new, rec.iterations,
                   rnorm, tol, rec.step_lengths.empty() ? 1.0 : rec.step_lengths.back());
    if (rnorm <= tol) {
      rec.converged = true;
      force_scale = scale;
      return;
    }
    if (!std::isfinite(rnorm) || rnorm > options_.divergence_factor * std::max(first_norm, 1e-300)) {
      rec.failure =
          "diverged: |r| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) + " iterations";
      return;
    }
    // Stalled: the line search damped each of the last kStallWindow corrections to less
    // than half and |r_f| fell by less than half over them. A smaller increment converges
    // sooner than crawling on to max_iterations (full steps that converge slowly, as with
    // an inexact contact tangent, are left to go on).
    const std::size_t nr = rec.residual_norms.size(), ns = rec.step_lengths.size();
    const bool damped = ns >= kStallWindow && std::all_of(rec.step_lengths.end() - kStallWindow, rec.step_lengths.end(),
                                                          [](double a) { return a < 0.5; });
    if (rec.iterations >= kStallAfter && damped && nr > kStallWindow &&
        rnorm > 0.5 * rec.residual_norms[nr - 1 - kStallWindow]) {
      rec.failure = "stalled: |r| " + detail::short_number(rnorm) + " after " + std::to_string(rec.iterations) +
                    " iterations, damped corrections that did not halve |r| in " + std::to_string(kStallWindow) +
                    " iterations";
      return;
    }
    if (rec.iterations >= options_.max_iterations) {
      rec.failure = "no convergence in " + std::to_string(options_.max_iterations) + " iterations (|r| " +
                    detail::short_number(rnorm) + ", tolerance " + detail::short_number(tol) + ")";
      return;
    }
    const Residual st = evaluate(lam_new, xt, true);
    if (!st.a.ok) {
      rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + st.a.message;
      return;
    }
    const VecX rf = free_.restrict(st.residual);
    const linalg::SolveReport& sr = solver_->factorize(pattern_->matrix());
    if (!sr.ok()) {
      rec.failure = "linear solve " + sr.brief();
      return;
    }
    if (trace) trace_tangent("tangent", *solver_, pattern_->matrix(), sr, model_, free_, xt);
    const VecX dxf = solver_->solve(-rf);
    ++rec.iterations;
    if (!dxf.allFinite()) {
      rec.failure = "linear solve returned non-finite values";
      return;
    }
    const VecX dx = free_.expand(dxf);
    // SF_NEWTON_CHECK=1 (with the trace): the tangent along the correction against a
    // central difference of the residual there, and the linear solve's own residual.
    static const bool check = trace && std::getenv("SF_NEWTON_CHECK") != nullptr;
    if (check && dxf.size() > 0) {
      const double h = 1e-6 / std::max(dxf.lpNorm<Eigen::Infinity>(), 1e-300);
      const Residual kd = evaluate(lam_new, xt, false, &dx);
      const Residual rp = evaluate(lam_new, xt + h * dx, false), rm = evaluate(lam_new, xt - h * dx, false);
      if (kd.a.ok && rp.a.ok && rm.a.ok) {
        const VecX kdf = free_.restrict(kd.a.tangent_times);
        const VecX fd = free_.restrict(rp.residual - rm.residual) / (2 * h);
        std::fprintf(stderr, "newton check: |dx| %.3e  |K dx + r| / |r| %.2e  |K dx - FD| / |K dx| %.2e\n",
                     dxf.lpNorm<Eigen::Infinity>(), (kdf + rf).norm() / rf.norm(), (kdf - fd).norm() / kdf.norm());
      }
    }
    // Round-off floor: a correction this small cannot reduce |r| further.
    if (dxf.size() == 0 || dxf.lpNorm<Eigen::Infinity>() <= kIncrementTolRel * length_scale_) {
      xt += dx;
      rec.step_lengths.push_back(1.0);
      rec.converged = true;
      force_scale = st.scale;
      return;
    }
    std::pair<double, double> at_step{0.0, 0.0};
    double alpha = 1.0;
    if (options_.line_search) {
      bool bounced = false;
      alpha = line_search(lam_new, xt, dx, dxf, rf, rnorm, scale, rec, at_step, may_bounce, &bounced);
      if (alpha < 0.0) return;
      if (bounced && since < 0) {
        x_ref = xt;
        r_ref = rnorm;
        scale_ref = scale;
        since = 0;
        if (trace) std::fprintf(stderr, "newton:   watchdog: full step to |r| %.3e\n", at_step.first);
      }
    } else {
      const Residual trial = evaluate(lam_new, xt + dx, false);
      if (!trial.a.ok) {
        rec.failure = "iteration " + std::to_string(rec.iterations) + ": " + trial.a.message;
        return;
      }
      at_step = {free_.restrict(trial.residual).norm(), trial.scale};
    }
    xt += alpha * dx;
    rec.step_lengths.push_back(alpha);
    rnorm = at_step.first;
    scale = at_step.second;
  }
}

double LoadStepping::line_search(double lam_new, const VecX& xt, const VecX& dx, const VecX& dxf, const VecX& rf,
                                 double rnorm, double scale, StepRecord& rec, std::pair<double, double>& at_step,
                                 bool allow_bounce, bool* bounced) {
  // Trials along dx from the full step. |r| alone is a poor merit when the fibres are
  // stiff: a full Newton step towards the solution may raise |r| (a second-order fibre
  // stretch) while the potential falls, and halving on |r| then crawls with steps of
  // 1/128 for tens of iterations. So a trial is taken when
  //   |r_f| fell sufficiently (Armijo on |r_f|), or
  //   dx is a descent direction of the potential (s0 = dx . r_f < 0: K_ff positive
  //   definite along dx) and the slope s = dx . r_f(trial) <= kSlopeAccept |s0|
  //   (the potential fell: by the trapezoid rule Pi(step) - Pi(0) ~ step (s0 + s) / 2),
  //   unless the trial is wild: |r_f| > kMaxGrowth max(|r_f|, force scale).
  // A rejected trial is followed by the root of the slope's secant when it overshot the
  // line minimum (s > 0), else by half the step. Inverted elements reject a trial.
  // Failing all, the trial with the smallest |r_f|.
  constexpr double kSlopeAccept = 0.8, kMaxGrowth = 1e3, kMinShrink = 0.1, kMaxShrink = 0.7;
  const double s0 = dxf.dot(rf);
  const bool descent = s0 < 0.0;
  const double wild = kMaxGrowth * std::max(rnorm, scale);
  double step = 1.0, best_norm = std::numeric_limits<double>::infinity(), alpha = -1.0;
  for (int ls = 0; ls <= options_.max_line_search; ++ls) {
    const Residual trial = evaluate(lam_new, xt + step * dx, false);
    if (!trial.a.ok) {
      step *= 0.5;
      continue;
    }
    const VecX rt = free_.restrict(trial.residual);
    const double norm = rt.norm();
    const double s = dxf.dot(rt);
    if (norm < best_norm) {
      best_norm = norm;
      alpha = step;
      at_step = {norm, trial.scale};
    }
    const bool armijo = norm <= (1.0 - detail::kSufficientDecrease * step) * rnorm;
    const bool downhill = descent && s <= kSlopeAccept * std::abs(s0) && norm <= wild;
    if (armijo || downhill) {
      at_step = {norm, trial.scale};
      return step;
    }
    if (ls == 0 && allow_bounce && norm <= kBounce * rnorm) {
      at_step = {norm, trial.scale};
      if (bounced) *bounced = true;
      return step;
    }
    double next = 0.5;
    if (descent && s > 0.0 && std::isfinite(s)) next = std::clamp(s0 / (s0 - s), kMinShrink, kMaxShrink);
    step *= next;
  }
  if (alpha < 0.0)
    rec.failure = "iteration " + std::to_string(rec.iterations) + ": every line-search trial inverted an element";
  return alpha;
}

}  // namespace

StaticResult solve_static(const Model& model, const Eigen::Ref<const VecX>& x_start,
                          const std::vector<PrescribedDof>& prescribed, const LoadFunction& load_at, bool unsymmetric,
                          const StaticOptions& options) {
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
  LoadStepping steps(model, x_start, load_at, unsymmetric, options);
  if (const std::string why = steps.classify(prescribed); !why.empty()) return invalid(why);
  if (const Assembly a0 = model.assemble(x_start, false); !a0.ok) return invalid("start state: " + a0.message);

  VecX x = x_start;
  double lambda = 0.0;
  double increment = std::min(options.initial_increment, options.max_increment);
  // A run's steps start with the increment the last solve ended with (had it to cut
  // back, the next step would otherwise fail the same way first).
  if (options.workspace && options.workspace->next_increment > 0.0)
    increment = std::clamp(options.workspace->next_increment, options.min_increment, increment);
  int attempts = 0;
  int in_a_row = 0;  // steps converged since the last cut-back or growth (regrow_after)
  int failures = 0;  // sub-steps failed in this solve (give_up_after)
  // StaticOptions::extrapolate: the first predictor starts from the previous increment.
  const double span = options.clock.end - options.clock.start;
  VecX extrapolated;
  if (options.extrapolate && options.workspace && options.workspace->last_increment.size() == n &&
      options.workspace->last_span > 0.0 && span > 0.0)
    extrapolated = (span / options.workspace->last_span) * options.workspace->last_increment;
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
    VecX xt;
    std::string why;
    // The first attempt from the extrapolated state when it is admissible.
    VecX guess;
    if (attempts == 1 && extrapolated.size() == n) {
      guess = x + lam_new * extrapolated;
      if (!model.assemble(guess, false).ok) guess.resize(0);
    }
    LoadStepping::Predicted predicted = steps.predict(lam_new, guess.size() == n ? guess : x, xt, rec, why);
    if (guess.size() == n && predicted == LoadStepping::Predicted::kInadmissible)
      predicted = steps.predict(lam_new, x, xt, rec, why);
    if (predicted == LoadStepping::Predicted::kInadmissible) return invalid(why);
    if (predicted == LoadStepping::Predicted::kOk) steps.correct(lam_new, xt, rec, report.force_scale);
    if (rec.converged) {
      x = xt;
      lambda = lam_new;
      steps.converged(lambda, x);
      ++in_a_row;
      if (rec.iterations <= options.easy_iterations ||
          (options.regrow_after > 0 && in_a_row >= options.regrow_after)) {
        increment = std::min(options.max_increment, increment * options.growth);
        in_a_row = 0;
      }
      report.add(std::move(rec));
      continue;
    }
    why = rec.failure;
    report.add(std::move(rec));
    in_a_row = 0;
    ++failures;
    if (options.give_up_after > 0 && failures >= options.give_up_after) {
      report.status = SolveStatus::kStepFailed;
      report.message = "load step from lambda " + detail::short_number(lambda) + " failed (" + why + "); " +
                       std::to_string(failures) + " sub-steps failed, the last of increment " +
                       detail::short_number(increment) + " (give_up_after)";
      break;
    }
    increment *= 0.5;
    if (increment < options.min_increment) {
      report.status = SolveStatus::kStepFailed;
      report.message = "load step from lambda " + detail::short_number(lambda) + " failed (" + why +
                       "); increment cut back below min_increment " + detail::short_number(options.min_increment);
      break;
    }
  }
  if (options.workspace) options.workspace->next_increment = increment;
  if (options.workspace && options.extrapolate && lambda >= 1.0) {
    TangentWorkspace& w = *options.workspace;
    if (span > 0.0) {
      w.last_increment = x - x_start;
      w.last_span = span;
    } else if (w.last_span > 0.0 && w.last_increment.size() == n) {
      // A solve with the time standing still (a step repeated for multiplier updates)
      // belongs to the step before it: its correction joins that step's increment, over
      // that step's span (overwriting the span with 0 turned the next step's
      // extrapolation off).
      w.last_increment += x - x_start;
    }
  }
  if (lambda >= 1.0) {
    report.status = SolveStatus::kConverged;
    report.message.clear();
  }
  report.load_factor = lambda;
  result.positions = x;
  result.reactions = steps.final_residual(lambda, x).residual;
  return result;
}

StaticResult solve_static_constrained(Model& model, const Eigen::Ref<const VecX>& x_start,
                                      const std::vector<PrescribedDof>& prescribed, const LoadFunction& load,
                                      bool unsymmetric, const StaticOptions& options, const UzawaOptions& uzawa,
                                      UzawaReport* report) {
  UzawaReport rep;
  StaticResult r = solve_static(model, x_start, prescribed, load, unsymmetric, options);
  // Repeats start at the step's end with the time standing still there and the rates
  // measured from the step's start.
  const VecX step_start = options.clock.previous ? *options.clock.previous : VecX(x_start);
  StaticOptions repeat = options;
  repeat.clock = {options.clock.end, options.clock.end, &step_start,
                  options.clock.previous ? options.clock.previous_time : options.clock.start};
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
                           " multiplier updates (max |mean J - 1| " + detail::short_number(rep.max_g_J) +
                           ", max |mean (I4 - 1)/2| " + detail::short_number(rep.max_g_T) + ", tolerance " +
                           detail::short_number(uzawa.tolerance) + ")";
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
      const LoadFunction full = [&load](double, const VecX& x, bool want_tangent) {
        return load(1.0, x, want_tangent);
      };
      const StaticResult again = solve_static(model, r.positions, prescribed, full, unsymmetric, repeat);
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
