#pragma once
// `simform run`: runs a case and writes its results atomically into one folder. The
// driver (run.cpp) reads like its table of contents:
//
//   build the problem        forming/case/build.hpp: model, loads, prescribed dofs, once
//   choose the stepper       forming/solve/stepper.hpp: load control, dynamics or arc
//                            length, with the solver settings translated once
//   step, with an observer   forming/run/recorder.hpp: every converged step goes to the
//                            recorder, which writes the outputs (forming/output/)
//   summarise                the last frame, result.pvd, history.csv, summary.json,
//                            committed together; then the grid file
//
// Outputs (forming/output/*.hpp; docs/forming.md):
//   result.pvd, steps/step_NNNN.vtu   ParaView series (time = load factor)
//   history.csv                       one row per converged step (row 0 = reference)
//   summary.json                      inputs, parameters, status, counts, timings
//   restart.json                      the state at the last written frame (--restart)
//
// A step that cannot converge ends the run: the steps written so far plus the last
// converged step are committed with status "not_converged" (the caller exits 1).
// With a grid file requested (RunOptions::grid_out), the final positions of an n x n
// grid of marks on the top surface of one ply are written in the grid-file format of
// CONTRACT.md (id,X,Y,Z,x,y,z,i,j), only when the run converged.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/case/schema.hpp"

namespace sf::forming {

struct RunOptions {
  std::string out_dir;   // required
  std::string grid_out;  // empty: no grid file
  int grid_marks = 21;   // marks per side (>= 2)
  std::string grid_ply;  // empty: the first ply
  bool quiet = false;    // no progress lines on stderr
  bool restart = false;  // continue from out_dir/restart.json (the last written step)
  int stop_after = 0;    // > 0: stop cleanly after this many steps of this run (restart later)
  std::string command_line = "simform run";
  // Throws sf::UsageError naming the option.
  void validate() const;
};

struct RunReport {
  enum class Status { kConverged, kNotConverged, kStopped };  // kStopped: --stop-after reached
  Status status = Status::kNotConverged;
  std::string message;  // names the step on failure
  int steps_converged = 0;
  double load_factor = 0.0;
  double final_residual = 0.0;  // N
  int total_iterations = 0;
  int multiplier_updates = 0;             // Uzawa updates of the constraint multipliers
  Vec3 tool_displacement = Vec3::Zero();  // last converged step, mm
  Vec3 tool_force = Vec3::Zero();         // N
  Vec3 max_displacement = Vec3::Zero();   // displacement of largest magnitude over the nodes, mm
  double seconds = 0.0;
  bool ok() const { return status != Status::kNotConverged; }  // converged or stopped on request
  std::string brief() const;
};

// Runs the case and writes the outputs (see header). Throws sf::InputError / sf::Error
// for bad input or unwritable outputs; non-convergence is reported, not thrown.
RunReport run_case(const FormingCase& spec, const RunOptions& options);

}  // namespace sf::forming
