#pragma once
// The StepObserver of `simform run` (forming/solve/stepper.hpp): it writes the outputs of
// a run as the steps converge and fills its RunReport.
//
//   start()    the state stepping starts from: the reference state (history row 0 and
//              frame 0 written), or the state of OUT/restart.json (its history rows and
//              the frames still in the folder kept);
//   on_step()  per converged step: a history row, the report fields, a progress line;
//              every `output.every` steps (and at the last step, and where --stop-after
//              stops the run) a frame and restart.json;
//   finish()   the last converged step's frame if it was not written, result.pvd,
//              history.csv and summary.json, committed together; then the grid file of
//              a converged run.
//
// Everything is written into an io::AtomicOutputDir whose working folder is OUT.partial
// (kept when the run is killed): the frames and restart.json land there together, so a
// `--restart` after a kill continues in it with every frame written so far (tool and
// contact parts too); a `--restart` after a clean stop links the committed OUT into it.
// Committing replaces OUT whole (the outputs of an older run never stay beside these).
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "common/core/types.hpp"
#include "common/io/atomic_file.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/problem.hpp"
#include "forming/output/frames.hpp"
#include "forming/output/history.hpp"
#include "forming/output/restart.hpp"
#include "forming/run/run.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {

class RunRecorder final : public StepObserver {
 public:
  // `problem` must outlive the recorder. Creates the temporary output folder.
  RunRecorder(const FormingCase& spec, Problem& problem, const RunOptions& options);

  SteppingState start();
  StepAction on_step(const StepInfo& step, const SteppingState& state, const VecX& reactions) override;
  // seconds_build: time spent building the problem before the recorder was made
  // (summary.json timings).
  RunReport finish(const SteppingReport& stepping, double seconds_build);
  // The state read from restart.json (a restart; empty otherwise).
  const RestartState& restart_state() const { return restart_; }

 private:
  using Clock = std::chrono::steady_clock;
  void write_step(int k, double load_factor);  // frame k of the last converged state + restart.json
  std::string progress_line(const StepInfo& step) const;

  const FormingCase& spec_;
  Problem& problem_;
  const RunOptions& options_;
  const VecX X_;
  io::AtomicOutputDir out_;
  FrameSeries frames_;
  HistoryTable history_;
  std::string restart_path_;
  RestartState restart_;
  RunReport report_;

  // The time and rates of the last converged state, for the contact outputs and tool
  // reactions (rates over the last step, or the velocities of a dynamic run).
  InteractionContext context() const;

  SteppingState last_;                            // the last converged state (the start until a step converges)
  SteppingState previous_;                        // the one before it
  double last_time_ = 0.0, previous_time_ = 0.0;  // s
  bool have_previous_ = false;
  double start_load_factor_ = 0.0;
  int steps_this_run_ = 0;
  int last_written_ = 0;
  Clock::time_point created_;
  Clock::time_point stepping_started_;
  double seconds_write_ = 0.0;
  // Stabilised runs: the last step's dissipated energy (N mm), damping factor
  // (N s/mm^4), ratio to the strain energy, the largest ratio and whether the run warned.
  bool stabilised_ = false;
  double stabilisation_energy_ = 0.0, damping_ = 0.0, ratio_ = 0.0, max_ratio_ = 0.0;
  nlohmann::json branch_switches_ = nlohmann::json::array();  // summary.json "branch_switches"
  bool warned_ = false;
};

}  // namespace sf::forming
