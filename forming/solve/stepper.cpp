#include "forming/solve/stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "forming/solve/mass.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

// The end of a run at a load or time step that did not converge.
SteppingReport failed(SteppingReport out, int k, int n, double lambda, const std::string& why) {
  std::ostringstream os;
  os << "step " << k << " of " << n << " (load factor " << lambda << ") did not converge: " << why
     << "; results up to step " << (k - 1) << " are written. Try more steps, a larger max_iterations or a smaller "
     << "min_increment";
  out.status = SteppingReport::Status::kFailed;
  out.message = os.str();
  out.step_failure = "step " + std::to_string(k) + " failed: " + why;
  return out;
}

// Commits every interaction of the model at x, the step having started at `previous`.
void commit_interactions(Model& model, const VecX& x, const InteractionContext& context) {
  for (int i = 0; i < model.n_interactions(); ++i) model.interaction(i).commit(x, context);
}

// Asks every interaction to update its multipliers at x; true when all constraints were
// met (nothing updated). `worst` gets the largest violation relative to its tolerance.
bool update_interactions(Model& model, const VecX& x, const InteractionContext& context, std::string& worst) {
  bool all = true;
  double ratio = 0.0;
  for (int i = 0; i < model.n_interactions(); ++i) {
    const MultiplierUpdate u = model.interaction(i).update_multipliers(x, context);
    all = all && u.converged;
    if (u.tolerance > 0.0 && u.violation / u.tolerance > ratio) {
      ratio = u.violation / u.tolerance;
      std::ostringstream os;
      os << model.interaction(i).name() << ": " << u.violation << " (tolerance " << u.tolerance << ")";
      worst = os.str();
    }
  }
  return all;
}

// The first output step beyond load factor `lambda` (n + 1 when none is left).
int first_step_after(double lambda, int n) {
  int first = 1;
  while (first <= n && double(first) / n <= lambda * (1.0 + 1e-12)) ++first;
  return first;
}

class LoadStepper final : public Stepper {
 public:
  LoadStepper(Problem& problem, const StepperSettings& settings) : problem_(problem), settings_(settings) {
    // One tangent pattern and symbolic factorisation for all the steps (and repeats).
    if (!settings_.statics.workspace) settings_.statics.workspace = std::make_shared<TangentWorkspace>();
    if (settings_.stabilise.active()) {
      settings_.stabilise.validate();
      for (int i = 0; i < problem_.model.n_interactions() && !stabilisation_; ++i)
        stabilisation_ = dynamic_cast<ViscousStabilisation*>(&problem_.model.interaction(i));
      if (!stabilisation_) {
        auto s = std::make_shared<ViscousStabilisation>(problem_.model);
        stabilisation_ = s.get();
        problem_.model.add_interaction(std::move(s));
      }
      // Given c from the start; calibrated c after the first step (0 until then).
      stabilisation_->set_damping(settings_.stabilise.damping);
      dissipated_ = settings_.stabilise.start_energy;
    }
  }

  SteppingReport run(SteppingState& state, StepObserver& observer) override {
    SteppingReport out;
    const int n = settings_.steps;
    const int first = first_step_after(state.load_factor, n);
    out.nothing_left = first > n;
    const double lambda_start = state.load_factor;
    const double T = settings_.process_time;
    // A restart's first step starts with the sub-step the run would have taken next and,
    // with the extrapolating predictor, extrapolates with the rate the run had when it
    // stopped (increment per unit process time: the span is 1 s).
    const Index n_dofs = problem_.model.n_dofs();
    TangentWorkspace& ws = *settings_.statics.workspace;
    if (settings_.statics.extrapolate && ws.last_increment.size() == 0 && state.predictor_rate.size() == n_dofs) {
      ws.last_increment = state.predictor_rate;
      ws.last_span = 1.0;
    }
    if (ws.next_increment == 0.0 && state.next_increment > 0.0) ws.next_increment = state.next_increment;
    // Branch switching: a restart's start state is checked as a step's end is (its rates
    // at rest over one step's time).
    std::vector<BranchSwitch> pending;
    if (settings_.branch_switch.active() && first > 1 && first <= n) {
      const double t0 = state.load_factor * T;
      switch_branch(state.x, state.load_factor, first - 1, false,
                    InteractionContext{t0, nullptr, &state.x, t0 - T / n}, pending);
    }
    for (int k = first; k <= n; ++k) {
      const double lambda = double(k) / n;
      // Within the step the solver's factor s in [0, 1] runs from the previous load
      // factor to this one (from_lambda: where a retry after a branch switch starts).
      const double lambda_prev = k == first ? lambda_start : double(k - 1) / n;
      double from_lambda = lambda_prev;
      const LoadFunction step_load = [&](double s, const VecX& xs, bool want_tangent) {
        return problem_.loads.at(problem_.model, from_lambda + s * (lambda - from_lambda), xs, want_tangent);
      };
      // Process time over the step: tools move with it, rates are taken over it.
      StaticOptions statics = settings_.statics;
      statics.clock = {lambda_prev * T, lambda * T, nullptr, 0.0};
      // Branch switching: a stall is left for a switch after a few failed sub-steps, not
      // cut back to min_increment first (not while the damping is to be calibrated: that
      // takes the part of the first step that converged).
      const BranchSwitchOptions& bs = settings_.branch_switch;
      if (bs.active() && bs.retries > 0 && !needs_calibration()) statics.give_up_after = bs.give_up_after;
      std::vector<BranchSwitch> switches = std::move(pending);
      pending.clear();
      const std::vector<PrescribedDof> targets = problem_.prescriptions.at(lambda);
      // Stabilised: the converged sub-steps, for the energy they dissipate.
      std::vector<SubStep> substeps;
      if (stabilisation_)
        statics.on_substep = [&substeps](const VecX& from, double t0, const VecX& to, double t1) {
          substeps.push_back({from, to, t1 - t0});
        };
      UzawaReport uzawa;
      StaticResult r = solve_static_constrained(problem_.model, state.x, targets, step_load, problem_.loads.follower,
                                                statics, settings_.uzawa, &uzawa);
      out.multiplier_updates += uzawa.updates;
      out.total_iterations += r.report.total_iterations;
      // fraction: a first step that fails unstabilised calibrates c from the part of it
      // that converged and is solved again, stabilised, from its start.
      if (!r.report.ok() && needs_calibration() && r.report.load_factor > 0.0) {
        calibrate(state.x, r.positions, r.report.load_factor * (lambda - lambda_prev) * T);
        if (stabilisation_->damping() > 0.0) {
          substeps.clear();
          statics.workspace->next_increment = 0.0;
          r = solve_static_constrained(problem_.model, state.x, targets, step_load, problem_.loads.follower, statics,
                                       settings_.uzawa, &uzawa);
          out.multiplier_updates += uzawa.updates;
          out.total_iterations += r.report.total_iterations;
        }
      }
      // Branch switching: the failed step tried again from switched states.
      DampingBoost boost(stabilisation_);  // restores c when the step's solving is over
      if (!r.report.ok() && bs.active() && !needs_calibration())
        r = retry_switched(std::move(r), k, lambda, lambda_prev, state.x, from_lambda, statics, targets, step_load,
                           switches, boost, out);
      if (!r.report.ok()) {
        if (needs_calibration() && r.report.load_factor <= 0.0)
          r.report.message += "; stabilise fraction: no part of the step converged to calibrate the damping from: "
                              "give solver stabilise damping (N s/mm^4) instead";
        return failed(std::move(out), k, n, lambda, r.report.message);
      }
      // Augmented-Lagrangian interactions: update and solve the step again at its end
      // (the time standing still, rates still from the step's start) until all are met.
      const InteractionContext at_end{lambda * T, nullptr, &state.x, lambda_prev * T};
      std::string worst;
      int updates = 0;
      while (!update_interactions(problem_.model, r.positions, at_end, worst)) {
        if (updates == settings_.max_multiplier_updates)
          return failed(std::move(out), k, n, lambda,
                        "contact multipliers not converged after " + std::to_string(updates) +
                            " updates (largest penetration " + worst + ")");
        ++updates;
        ++out.contact_updates;
        StaticOptions repeat = settings_.statics;
        repeat.clock = {lambda * T, lambda * T, &state.x, lambda_prev * T};
        const LoadFunction full = [&](double, const VecX& xs, bool want_tangent) {
          return problem_.loads.at(problem_.model, lambda, xs, want_tangent);
        };
        const StaticResult again = solve_static_constrained(problem_.model, r.positions, targets, full,
                                                            problem_.loads.follower, repeat, settings_.uzawa, &uzawa);
        out.multiplier_updates += uzawa.updates;
        out.total_iterations += again.report.total_iterations;
        r.report.total_iterations += again.report.total_iterations;
        if (!again.report.ok()) return failed(std::move(out), k, n, lambda, again.report.message);
        r.positions = again.positions;
        r.reactions = again.reactions;
      }
      if (stabilisation_) {
        // The repeats moved the end of the last sub-step to the final state.
        if (!substeps.empty()) substeps.back().to = r.positions;
        for (const SubStep& s : substeps) dissipated_ += stabilisation_->dissipation(s.from, s.to, s.dt);
        if (needs_calibration()) calibrate(state.x, r.positions, (lambda - lambda_prev) * T);
      }
      boost.restore();
      commit_interactions(problem_.model, r.positions, at_end);
      const VecX step_start = state.x;
      state.x = r.positions;
      state.load_factor = lambda;
      state.next_increment = ws.next_increment;
      if (settings_.statics.extrapolate)
        state.predictor_rate = ws.last_span > 0.0 && ws.last_increment.size() == n_dofs
                                   ? VecX(ws.last_increment / ws.last_span)
                                   : VecX();
      StepInfo info{
          Control::kLoad,          k, n, lambda, lambda * T, r.report.total_iterations, r.report.n_cutbacks,
          r.report.last_residual()};
      if (stabilisation_) {
        info.stabilised = true;
        info.stabilisation_energy = dissipated_;
        info.damping = stabilisation_->damping();
      }
      // Branch switching after the step: its tangent over the step's rates (as Newton's
      // last one); the observer sees the converged state, the next step starts moved.
      VecX moved;
      if (settings_.branch_switch.active() && k < n)
        moved = switch_branch(state.x, lambda, k, false, InteractionContext{lambda * T, nullptr, &step_start, lambda_prev * T},
                              switches);
      info.branch_switches = switches;
      if (observer.on_step(info, state, r.reactions) == StepAction::kStop) {
        out.status = SteppingReport::Status::kStopped;
        return out;
      }
      if (moved.size() == state.x.size()) state.x = moved;
    }
    return out;
  }

 private:
  // The damping factor raised for the rest of a step (the last retry's
  // last_retry_damping) and put back when the step's solving is over: by restore(),
  // or on leaving the scope (a failed step).
  class DampingBoost {
   public:
    explicit DampingBoost(ViscousStabilisation* s) : s_(s) {}
    DampingBoost(const DampingBoost&) = delete;
    DampingBoost& operator=(const DampingBoost&) = delete;
    ~DampingBoost() { restore(); }
    // c times `factor` when there is a calibrated or given c and it is not raised yet.
    void raise(double factor) {
      if (factor > 1.0 && s_ && s_->damping() > 0.0 && from_ == 0.0) {
        from_ = s_->damping();
        s_->set_damping(factor * from_);
      }
    }
    void restore() {
      if (from_ > 0.0) s_->set_damping(from_);
      from_ = 0.0;
    }

   private:
    ViscousStabilisation* s_;
    double from_ = 0.0;  // c before it was raised (0: not raised)
  };

  // Branch switching: the failed step k (result r; started from step_start at
  // lambda_prev) once more from its last converged sub-step, moved along that state's
  // nearest-zero mode, at most `retries` times; twice the amplitude when the last retry
  // started from the same state (up to kMaxEscalation); the last retry cuts back to
  // min_increment, with last_retry_damping times c if asked. from_lambda (which
  // step_load reads) becomes where the retry starts. The result's counts include the
  // failed attempts'; its message, when it fails too, every attempt's.
  StaticResult retry_switched(StaticResult r, int k, double lambda, double lambda_prev, const VecX& step_start,
                              double& from_lambda,
                              const StaticOptions& statics, const std::vector<PrescribedDof>& targets,
                              const LoadFunction& step_load, std::vector<BranchSwitch>& switches, DampingBoost& boost,
                              SteppingReport& out) {
    const BranchSwitchOptions& bs = settings_.branch_switch;
    const double T = settings_.process_time;
    const int n = settings_.steps;
    double last_reached = -1.0, scale = 1.0;
    for (int retry = 0; !r.report.ok() && retry < bs.retries; ++retry) {
      const double reached = from_lambda + r.report.load_factor * (lambda - from_lambda);
      scale = std::abs(reached - last_reached) <= 1e-12 * std::max(1.0, std::abs(reached))
                  ? std::min(2.0 * scale, kMaxEscalation)
                  : 1.0;
      last_reached = reached;
      const double t_reached = reached * T;
      const InteractionContext at_reached =
          t_reached > lambda_prev * T ? InteractionContext{t_reached, nullptr, &step_start, lambda_prev * T}
                                      : InteractionContext{t_reached, nullptr, &r.positions, t_reached - T / n};
      const VecX x_reached = r.positions;
      VecX moved = switch_branch(x_reached, reached, k, true, at_reached, switches, scale);
      if (moved.size() == 0) break;
      from_lambda = reached;
      StaticOptions again = statics;
      again.clock = {reached * T, lambda * T, nullptr, 0.0};
      if (retry + 1 == bs.retries) {
        again.give_up_after = 0;
        // The last retry, if asked, with raised damping for the rest of this step (a snap
        // of a ply that no switch passes is damped through, as a dynamic step would); its
        // energy counted with that c, the step's earlier sub-steps too.
        boost.raise(bs.last_retry_damping);
      }
      again.workspace->next_increment = 0.0;  // a fresh start: the cut-backs were the old branch's
      const std::string before = r.report.message;
      const int spent = r.report.total_iterations, cut = r.report.n_cutbacks;
      UzawaReport uzawa;
      r = solve_static_constrained(problem_.model, moved, targets, step_load, problem_.loads.follower, again,
                                   settings_.uzawa, &uzawa);
      out.multiplier_updates += uzawa.updates;
      out.total_iterations += r.report.total_iterations;
      // The step's counts: its failed attempts' too.
      r.report.total_iterations += spent;
      r.report.n_cutbacks += cut;
      if (!r.report.ok())
        r.report.message = before + "; after a branch switch at load factor " + std::to_string(reached) + ": " +
                           r.report.message;
    }
    return r;
  }

  // Branch switching (forming/solve/branch_switch.hpp) at the converged state x (load
  // factor lambda) of step k: when its tangent under `context` is unstable (det K < 0 or
  // negative pivots), or always after a failure, x moved along the nearest-zero mode,
  // recorded in `log`; empty when x stays.
  VecX switch_branch(const VecX& x, double lambda, int k, bool after_failure, const InteractionContext& context,
                     std::vector<BranchSwitch>& log, double failure_scale = 1.0) {
    const std::vector<PrescribedDof> fixed = problem_.prescriptions.at(lambda);
    const ExternalLoad load = problem_.loads.at(problem_.model, lambda, x, problem_.loads.follower);
    const TangentMode tm = tangent_mode(problem_.model, x, fixed, context, &load.tangent, mode_workspace_,
                                        settings_.branch_switch.inverse_steps);
    if (!tm.ok) return VecX();
    const bool unstable = tm.determinant_sign < 0 || tm.negative_pivots > 0;
    if (!after_failure) {
      // A step's end still unstable right after a switch: Newton went back to the
      // unstable path (the imperfection was inside its basin), so the next switch is
      // twice as large, up to kMaxEscalation times the amplitude.
      escalation_ = unstable && switched_last_ ? std::min(2.0 * escalation_, kMaxEscalation) : 1.0;
      switched_last_ = unstable;
    }
    if (!(unstable || after_failure)) return VecX();
    const double amplitude = (after_failure ? failure_scale : escalation_) * settings_.branch_switch.amplitude;
    int sign = 0;
    VecX moved = perturbed(problem_.model, x, tm.mode, amplitude, context, sign);
    if (moved.size() == 0) return moved;
    BranchSwitch b;
    b.step = k;
    b.load_factor = lambda;
    b.after_failure = after_failure;
    b.determinant_sign = tm.determinant_sign;
    b.eigenvalue = tm.eigenvalue;
    b.spread = tm.spread;
    b.place = tm.place;
    b.amplitude = sign * amplitude;
    log.push_back(std::move(b));
    return moved;
  }

  struct SubStep {
    VecX from, to;
    double dt = 0.0;  // s
  };
  // fraction given and c not yet calibrated.
  bool needs_calibration() const {
    return stabilisation_ && settings_.stabilise.fraction > 0.0 && !(stabilisation_->damping() > 0.0);
  }
  // c = fraction dE_s dt / (dx^T M* dx) over the increment from x0 to x1 taking dt (s);
  // stays 0 when the increment stored no strain energy or did not move.
  void calibrate(const VecX& x0, const VecX& x1, double dt) {
    const Assembly a0 = problem_.model.assemble(x0, false), a1 = problem_.model.assemble(x1, false);
    if (!(a0.ok && a1.ok)) return;
    stabilisation_->set_damping(calibrated_damping(*stabilisation_, settings_.stabilise.fraction,
                                                   a1.strain_energy - a0.strain_energy, x1 - x0, dt));
  }

  Problem& problem_;
  StepperSettings settings_;
  ViscousStabilisation* stabilisation_ = nullptr;  // owned by the model; null: not stabilised
  double dissipated_ = 0.0;                        // N mm, from the run's start
  TangentWorkspace mode_workspace_;                // branch switching's tangents (apart from Newton's)
  static constexpr double kMaxEscalation = 8.0;
  double escalation_ = 1.0;     // the next switch's amplitude / the given one
  bool switched_last_ = false;  // the last step's end was switched
};

class DynamicStepper final : public Stepper {
 public:
  DynamicStepper(Problem& problem, const StepperSettings& settings)
      : problem_(problem), settings_(settings), mass_(mass_matrix(problem.model, problem.density)) {
    if (!settings_.dynamics.workspace) settings_.dynamics.workspace = std::make_shared<TangentWorkspace>();
  }

  SteppingReport run(SteppingState& state, StepObserver& observer) override {
    SteppingReport out;
    const int n = settings_.steps;
    const double end_time = settings_.end_time;
    const int first = first_step_after(state.load_factor, n);
    out.nothing_left = first > n;
    const double lambda_start = state.load_factor;
    const std::vector<TimedDof> moving = problem_.prescriptions.in_time(end_time);
    const ExternalForceFn external = [&](double t, const VecX& xs, bool want_tangent) {
      return problem_.loads.at(problem_.model, t / end_time, xs, want_tangent);
    };
    for (int k = first; k <= n; ++k) {
      const double lambda = double(k) / n;
      const double lambda_prev = k == first ? lambda_start : double(k - 1) / n;
      // Inertia: integrate over the output interval [t_prev, t], load factor t / end_time.
      DynamicOptions options = settings_.dynamics;
      options.start_time = lambda_prev * end_time;
      options.end_time = lambda * end_time;
      const DynamicResult r = solve_dynamic(problem_.model, mass_, state.x, state.v, moving, external, options);
      out.total_iterations += r.report.total_iterations;
      if (!r.report.ok()) return failed(std::move(out), k, n, lambda, r.report.message);
      commit_interactions(problem_.model, r.positions,
                          InteractionContext{options.end_time, &r.velocities, &state.x, options.start_time});
      state.x = r.positions;
      state.v = r.velocities;
      state.load_factor = lambda;
      const StepInfo info{
          Control::kDynamic,       k, n, lambda, lambda * end_time, r.report.total_iterations, r.report.n_cutbacks,
          r.report.last_residual()};
      if (observer.on_step(info, state, r.reactions) == StepAction::kStop) {
        out.status = SteppingReport::Status::kStopped;
        return out;
      }
    }
    return out;
  }

 private:
  Problem& problem_;
  StepperSettings settings_;
  linalg::SparseMatrix mass_;
};

class ArcLengthStepper final : public Stepper {
 public:
  ArcLengthStepper(Problem& problem, const StepperSettings& settings) : problem_(problem), settings_(settings) {}

  SteppingReport run(SteppingState& state, StepObserver& observer) override {
    SteppingReport out;
    const Model& model = problem_.model;
    const VecX X = model.reference_positions();
    const auto at_stop_displacement = [&](const VecX& x) {
      return settings_.stop_displacement > 0.0 &&
             largest_displacement(model, x, X).norm() >= settings_.stop_displacement;
    };
    const LoadFunction proportional = [&](double lambda, const VecX& xs, bool want_tangent) {
      return problem_.loads.at(model, lambda, xs, want_tangent);
    };
    int k = 0;
    bool stopped = false;
    const auto on_point = [&](const ArcLengthPoint& pt) {
      ++k;
      commit_interactions(problem_.model, pt.x, InteractionContext{0.0, nullptr, &state.x, 0.0});
      state.x = pt.x;
      state.load_factor = pt.lambda;
      const VecX reactions = model.assemble(state.x, false).force - proportional(pt.lambda, state.x, false).force;
      out.total_iterations += pt.iterations;
      const StepInfo info{Control::kArcLength, k, settings_.steps, pt.lambda, 0.0, pt.iterations, 0, pt.residual};
      stopped = observer.on_step(info, state, reactions) == StepAction::kStop;
      return stopped || at_stop_displacement(state.x);
    };
    const ArcLengthResult r = solve_arc_length(model, state.x, problem_.prescriptions.at(0.0), proportional,
                                               problem_.loads.follower, settings_.arc, on_point);
    if (stopped) {
      out.status = SteppingReport::Status::kStopped;
      return out;
    }
    const bool reached = state.load_factor >= 1.0 || at_stop_displacement(state.x);
    if (!(r.ok() && reached)) {
      out.status = SteppingReport::Status::kFailed;
      out.message = "arc-length continuation ended at load factor " + std::to_string(state.load_factor) + ": " +
                    r.message + "; results up to arc-length step " + std::to_string(k) +
                    " are written. Try a smaller arc_length or more steps";
    }
    return out;
  }

 private:
  Problem& problem_;
  StepperSettings settings_;
};

}  // namespace

std::unique_ptr<Stepper> make_stepper(Problem& problem, const StepperSettings& settings) {
  switch (settings.control) {
    case Control::kDynamic:
      return std::make_unique<DynamicStepper>(problem, settings);
    case Control::kArcLength:
      return std::make_unique<ArcLengthStepper>(problem, settings);
    case Control::kLoad:
      break;
  }
  return std::make_unique<LoadStepper>(problem, settings);
}

}  // namespace sf::forming
