#pragma once
// `simform run`: builds the model of a case (forming/case/case.hpp), steps the load factor
// lambda = k / steps (k = 1..steps) with the quasi-static Newton solver
// (forming/solve/static_solver.hpp; each step may be cut back inside), and writes the results
// atomically into one folder:
//
//   result.pvd              ParaView time series (time = load factor)
//   steps/step_NNNN.vtu     hexahedra tessellating every brick (samples per element from
//                           the case's output section); point data "displacement" (mm);
//                           cell data "cauchy_stress" (6: xx, yy, zz, xy, yz, xz, MPa),
//                           "fibre_direction" (unit, deformed, F a0/|F a0|),
//                           "fibre_stretch" (|F a0|), "ply" (body index), evaluated at
//                           each cell's centre
//   history.csv             one row per converged step (row 0 = reference state):
//                           step, load_factor, tool_ux, tool_uy, tool_uz (mean displacement
//                           of the first displacement condition's edge, mm), tool_fx,
//                           tool_fy, tool_fz (reaction on that edge, N: sum of the
//                           reactions of its value dofs), strain_energy (N mm),
//                           newton_iterations, cutbacks, residual (N)
//   summary.json            inputs, parameters, status ("converged" | "not_converged"),
//                           message, timings, final residual, outputs
//
// A step that cannot converge ends the run: the steps written so far plus the last
// converged step are committed with status "not_converged" (the caller exits 1).
// With a grid file requested (RunOptions::grid_out), the final positions of an n x n
// grid of marks on the top surface of one ply are written in the grid-file format of
// CONTRACT.md (id,X,Y,Z,x,y,z,i,j), only when the run converged.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/case/case.hpp"
#include "forming/model/loads.hpp"
#include "forming/solve/static_solver.hpp"

namespace sf::forming {

struct RunOptions {
  std::string out_dir;     // required
  std::string grid_out;    // empty: no grid file
  int grid_marks = 21;     // marks per side (>= 2)
  std::string grid_ply;    // empty: the first ply
  bool quiet = false;      // no progress lines on stderr
  bool restart = false;    // continue from out_dir/restart.json (the last written step)
  int stop_after = 0;      // > 0: stop cleanly after this many steps of this run (restart later)
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
  int multiplier_updates = 0;  // Uzawa updates of the constraint multipliers
  Vec3 tool_displacement = Vec3::Zero();  // last converged step, mm
  Vec3 tool_force = Vec3::Zero();         // N
  Vec3 max_displacement = Vec3::Zero();   // displacement of largest magnitude over the nodes, mm
  double seconds = 0.0;
  bool ok() const { return status != Status::kNotConverged; }  // converged or stopped on request
  std::string brief() const;
};

// Model of a case: its plies in order (body b = ply b), one material instance per ply
// (fibre direction from the layup angle).
Model build_model(const FormingCase& spec);
// The case's loads (forming/model/loads.hpp), each with its ramp: f_ext(lambda, x) =
// sum_i ramp_i(lambda) f_i(x).
struct CaseLoads {
  std::vector<std::pair<Ramp, LoadSet>> sets;
  bool follower = false;  // some load follows the deformation (unsymmetric tangent)
  bool empty() const { return sets.empty(); }
  ExternalLoad at(const Model& model, double lambda, const VecX& x, bool want_tangent) const;
};
CaseLoads build_loads(const FormingCase& spec, const Model& model);
// Prescribed dofs at load factor lambda (global numbering of build_model()).
std::vector<PrescribedDof> prescribed_at(const FormingCase& spec, const Model& model, double lambda);

// Runs the case and writes the outputs (see header). Throws sf::InputError / sf::Error
// for bad input or unwritable outputs; non-convergence is reported, not thrown.
RunReport run_case(const FormingCase& spec, const RunOptions& options);

}  // namespace sf::forming
