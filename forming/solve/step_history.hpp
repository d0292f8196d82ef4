#pragma once
// The record of a stepping solve, one type for the static (load-factor steps), dynamic
// (time steps) and arc-length solvers: every attempted step, the counters, and the
// residual of the last converged step. StaticReport and DynamicReport extend it with
// what only they have (force scale; time-step range), so callers that only need "did it
// converge, in how many iterations, to which residual" read any of them alike.
//
//   attempt 1  target 0.5  converged  iterations 4  |r| 3e-2 1e-5 2e-11
//   attempt 2  target 1.0  failed     (cut back: increment halved)
//   attempt 3  target 0.75 converged  ...                      <- last_residual() here
//
// Units: residual norms in N (the 2-norm over the free dofs).
#include <string>
#include <vector>

namespace sf::forming {

// One attempted step: a load step of the static solver, a time step of the dynamic one.
struct StepRecord {
  double target = 0.0;     // load factor (static) or time (dynamic, s) it aims at
  double increment = 0.0;  // its load-factor increment or time step (s)
  bool converged = false;
  int iterations = 0;                  // Newton solves (predictor included)
  std::vector<double> residual_norms;  // |r_f| after the predictor and after each correction, N
  std::vector<double> step_lengths;    // line-search factor of each correction (1 = full)
  std::string failure;                 // why it failed (empty when converged)
};

enum class SolveStatus {
  kConverged,     // the end was reached (load factor 1, end_time) with every step converged
  kStepFailed,    // a step was cut back below the smallest increment, max_steps was
                  // reached, or a step failed fatally; see the message
  kInvalidStart,  // the start state or an input is not admissible (inverted element,
                  // prescribed dof out of range, wrong sizes)
};
// "converged", "step-failed", "invalid-start".
std::string to_string(SolveStatus status);

struct StepHistory {
  using Status = SolveStatus;
  Status status = Status::kStepFailed;
  std::string message;  // why it stopped early (empty when converged)
  int n_converged_steps = 0;
  int n_cutbacks = 0;
  int total_iterations = 0;       // Newton solves of every attempt, converged or not
  std::vector<StepRecord> steps;  // attempted steps in order (unless the solver was told not to keep them)

  bool ok() const { return status == Status::kConverged; }
  // |r_f| at the end of the last converged step (N); 0 before the first.
  double last_residual() const { return last_residual_; }
  // Counts an attempted step (iterations; converged or cut back) and keeps its record
  // when `keep`.
  void add(StepRecord step, bool keep = true);
  // "in N steps (C cut-backs), I Newton iterations", the part every brief shares.
  std::string counts() const;

 private:
  double last_residual_ = 0.0;
};

}  // namespace sf::forming
