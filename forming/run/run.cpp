#include "forming/run/run.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "forming/case/model_checks.hpp"
#include "forming/case/build.hpp"
#include "forming/model/problem.hpp"
#include "forming/run/recorder.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// The options that refer to the case: --grid-ply must name one of its plies.
void check_options_against(const FormingCase& spec, const RunOptions& options) {
  if (!options.grid_ply.empty() && spec.find_ply(options.grid_ply) < 0)
    throw UsageError("--grid-ply: no ply named '" + options.grid_ply + "' in " + spec.file);
}

}  // namespace

void RunOptions::validate() const {
  if (out_dir.empty()) throw UsageError("--out: an output folder is required");
  if (grid_marks < 2) throw UsageError("--grid-marks: expected at least 2, found " + std::to_string(grid_marks));
}

std::string RunReport::brief() const {
  std::ostringstream os;
  if (status == Status::kStopped)
    os << message;
  else if (ok())
    os << "converged: " << steps_converged << " steps, " << total_iterations << " Newton iterations, |r| "
       << sci(final_residual) << " N";
  else
    os << "not converged: " << message;
  return os.str();
}

RunReport run_case(const FormingCase& spec, const RunOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  options.validate();
  check_options_against(spec, options);

  // Build the problem and translate the solver settings, once. Large models take a while
  // to set up: say how large first.
  const ModelEstimate size = estimate_model(spec);
  cli::status(options.quiet, fmt::format("simform: setting up {} unknowns (about {:.0f} MB to solve)", size.unknowns,
                                         size.total_bytes() / 1e6));
  Problem problem = build_problem(spec);
  StepperSettings settings = stepper_settings(spec);
  const double seconds_build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  cli::status(options.quiet, fmt::format("simform: model set up in {:.1f} s; the first step also analyses the "
                                         "matrix pattern",
                                         seconds_build));

  // The recorder writes every output; stepping starts where it says (reference or restart).
  RunRecorder recorder(spec, problem, options);
  SteppingState state = recorder.start();
  if (options.restart && settings.control == Control::kArcLength)
    throw UsageError("--restart: not available with solver control arc_length");
  // A stabilised run restarts with the damping factor it had (calibrated or given) and
  // the energy dissipated so far.
  if (options.restart && settings.stabilise.active() && recorder.restart_state().stabilisation_damping > 0.0) {
    settings.stabilise.fraction = 0.0;
    settings.stabilise.damping = recorder.restart_state().stabilisation_damping;
    settings.stabilise.start_energy = recorder.restart_state().stabilisation_energy;
  }

  // Step with the chosen stepper, the recorder observing every converged step.
  const std::unique_ptr<Stepper> stepper = make_stepper(problem, settings);
  const SteppingReport stepping = stepper->run(state, recorder);

  // Summarise: last frame, result.pvd, history.csv, summary.json; then the grid file.
  return recorder.finish(stepping, seconds_build);
}

}  // namespace sf::forming
