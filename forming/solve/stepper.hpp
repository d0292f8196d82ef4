#pragma once
// Steppers: how a run walks a Problem (forming/model/problem.hpp) from its start to its
// end, one output step at a time, behind one interface, so the run driver
// (forming/run/run.hpp) reads the same whichever is chosen:
//
//   LoadStepper       quasi-static load control: step k of n solves for the load
//                     factor k / n with solve_static_constrained (cut back inside the
//                     step; Uzawa updates of constrained bodies' multipliers); within
//                     the step the loads move from the previous factor to the new one.
//                     The process time is lambda * process_time: interactions see it
//                     (tools move with it) and take their rates over the step
//                     (ProcessClock); interactions with multipliers (augmented-Lagrangian
//                     contact) are updated and the step solved again until each reports
//                     its constraint met (at most max_multiplier_updates times);
//                     with branch switching (forming/solve/branch_switch.hpp) a step
//                     whose converged tangent is unstable hands the next step its state
//                     moved along the nearest-zero mode, and a failed step gives up after
//                     a few failed sub-steps in a row and is tried again from its last
//                     converged sub-step so moved (BranchSwitchOptions: give_up_after,
//                     retries);
//   DynamicStepper    implicit dynamics: step k integrates the output interval
//                     [(k - 1) T / n, k T / n] with solve_dynamic (time steps cut back
//                     and regrown inside); load factor t / T, starting at rest;
//   ArcLengthStepper  Crisfield's arc length: one continuation from the reference
//                     state, every converged point a step; it ends past load factor 1
//                     (or at stop_displacement), with at most n steps.
//
//   state (x, v, lambda) --> [stepper] --step k converged--> StepObserver::on_step
//                                |                               (outputs, progress,
//                                v                                may stop the run)
//                         SteppingReport (finished | stopped | failed: which step, why)
//
// Load and time steppers start at the first step beyond the state's load factor (a
// restart); the arc-length stepper always starts from the reference state. After every
// converged step each interaction of the model is committed (Interaction::commit, with
// the step's start state as `previous`), before the observer sees the step.
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/model/problem.hpp"
#include "forming/solve/arc_length.hpp"
#include "forming/solve/branch_switch.hpp"
#include "forming/solve/dynamic_solver.hpp"
#include "forming/solve/static_solver.hpp"
#include "forming/solve/stabilisation.hpp"

namespace sf::forming {

enum class Control { kLoad, kDynamic, kArcLength };

// Solver settings of a run, translated once from the case (forming/case/build.hpp).
struct StepperSettings {
  Control control = Control::kLoad;
  int steps = 10;                   // output steps (arc length: the most steps)
  StaticOptions statics;            // kLoad
  UzawaOptions uzawa;               // kLoad with constrained bodies
  double process_time = 1.0;        // kLoad: s per unit load factor (t = lambda process_time)
  int max_multiplier_updates = 30;  // kLoad: augmented-Lagrangian repeats of a step
  // kLoad: viscous stabilisation (forming/solve/stabilisation.hpp). When active the
  // load stepper uses the model's ViscousStabilisation interaction, adding one when the
  // model has none; with `fraction` it calibrates c from the first step.
  StabiliseOptions stabilise;
  // kLoad: branch switching at a bifurcation (forming/solve/branch_switch.hpp): after a
  // converged step whose tangent is unstable, and once more for a failed step (at most
  // branch_switch.retries times a step), the state moves along the nearest-zero eigenmode.
  BranchSwitchOptions branch_switch;
  DynamicOptions dynamics;          // kDynamic: per output interval (its times are set per step)
  double end_time = 1.0;            // kDynamic, s
  ArcLengthOptions arc;             // kArcLength
  double stop_displacement = 0.0;   // kArcLength: also end when max |u| reaches this, mm (0: off)
};

// The state stepping starts from and, as it goes, the last converged state.
struct SteppingState {
  VecX x;                    // positions (n_dofs, mm)
  VecX v;                    // velocities (n_dofs, mm/s); used by dynamic runs
  double load_factor = 0.0;  // of x
  // Load control with the extrapolating predictor (StaticOptions::extrapolate): the rate
  // the next step's first iterate extrapolates with, the last step's increment of
  // positions over its process time (n_dofs, mm/s); empty: none (the first step). A
  // restart keeps it (restart.json `predictor_rate`), so a restarted step starts as it
  // would have in the uninterrupted run.
  VecX predictor_rate{};
  // Load control: the sub-step (fraction of a step) the next step starts with, the one
  // the last step's solve ended with (cut back, or regrown); 0: a whole step. A restart
  // keeps it too (restart.json `next_increment`).
  double next_increment = 0.0;
};

// A branch switch (forming/solve/branch_switch.hpp): where, and along which mode.
struct BranchSwitch {
  int step = 0;              // the step it belongs to
  double load_factor = 0.0;  // of the state moved
  bool after_failure = false;  // a failed step's last converged sub-step (else: the step's end)
  int determinant_sign = 0;    // of that state's tangent
  double eigenvalue = 0.0;     // nearest zero, / max |K_ii|
  double spread = 1.0;         // its eigen-residual (small: a real eigenvalue)
  ModePlace place;             // where the mode is largest, each ply's share
  double amplitude = 0.0;      // mm, signed (the side of lower stored energy)
};

// A converged step as the observer sees it.
struct StepInfo {
  Control control = Control::kLoad;
  int index = 0;    // k, 1-based
  int n_steps = 0;  // requested steps (arc length: the most)
  double load_factor = 0.0;
  double time = 0.0;      // s: load factor x end_time (dynamic) or x process_time (load control); 0 for arc length
  int iterations = 0;     // Newton iterations of the step
  int cutbacks = 0;       // cut-backs inside the step
  double residual = 0.0;  // |r_f| at its end, N
  // Load control with stabilisation: the energy it dissipated from the run's start to
  // the end of this step (N mm) and its damping factor c (N s/mm^4; 0 before calibration).
  bool stabilised = false;
  double stabilisation_energy = 0.0;
  double damping = 0.0;
  // Branch switches of this step: after a failed attempt (the step then converged) and
  // after its end (the next step starts from the moved state; the step's own results are
  // the unmoved converged state's).
  std::vector<BranchSwitch> branch_switches{};
};

enum class StepAction { kContinue, kStop };

class StepObserver {
 public:
  virtual ~StepObserver() = default;
  // After converged step `step`: the state reached and the support reactions there
  // (n_dofs, N: f - f_ext, non-zero on prescribed dofs). kStop ends the run after it.
  virtual StepAction on_step(const StepInfo& step, const SteppingState& state, const VecX& reactions) = 0;
};

struct SteppingReport {
  enum class Status { kFinished, kStopped, kFailed };
  Status status = Status::kFinished;
  std::string message;         // kFailed: names the step and what to try
  std::string step_failure;    // kFailed in a load or time step: "step k failed: <solver message>"
  bool nothing_left = false;   // the start state was already at the last step (a finished run restarted)
  int total_iterations = 0;    // Newton iterations (load and time steps: failed attempts included)
  int multiplier_updates = 0;  // Uzawa updates of the constraint multipliers
  int contact_updates = 0;     // augmented-Lagrangian repeats of steps for interactions
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  // Steps from `state` (updated to the last converged state) until the end, a failure
  // or the observer's kStop.
  virtual SteppingReport run(SteppingState& state, StepObserver& observer) = 0;
};

// The stepper of settings.control for `problem` (which must outlive it; its model's
// multipliers change during load control). Throws sf::InputError for a dynamic problem
// whose mass matrix cannot be built.
std::unique_ptr<Stepper> make_stepper(Problem& problem, const StepperSettings& settings);

}  // namespace sf::forming
