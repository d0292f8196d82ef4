#pragma once
// summary.json of a run (CONTRACT.md; docs/forming.md "Outputs"):
//
//   tool, version, command_line, inputs {case}
//   parameters   the case as used: units, materials (with the TI law's small-strain
//                moduli), plies (with fibre directions), boundary conditions, solver,
//                output, model (dofs, element, quadrature)
//   loads        each load with its ramp
//   analysis     "quasi-static (...)", "quasi-static, follower loads (...)" or "dynamic
//                (integrator, ...)", the brackets saying "no contact", "contact between
//                plies", "contact with tools" or "contact between plies and with tools"
//   time         dynamic runs: end_time_s and the time reached, time_s
//   status       "converged" | "stopped" | "not_converged", message
//   restart      {file, restarted, from_load_factor}
//   steps        {requested, converged, written}
//   load_factor, final_residual (N), newton_iterations, multiplier_updates
//   tool_edge    {edge, displacement (mm), force (N)}, max_displacement (mm)
//   timings_s    {build, solve, write, total}; outputs; grid_out; units
//   stabilisation  stabilised runs: {fraction, damping (N s/mm^4, in use), energy (N mm,
//                dissipated to the last step), ratio (to the strain energy there),
//                max_ratio (over the steps), warn_ratio, quasi_static (max_ratio <= warn_ratio)}
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/types.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// What summary.json says about the run (the case and the model give the rest).
struct RunSummary {
  std::string command_line;
  std::string status;  // "converged" | "stopped" | "not_converged"
  std::string message;
  bool follower_loads = false;  // some load follows the deformation
  double load_factor = 0.0;     // of the last converged step (dynamic: time / end_time)
  double final_residual = 0.0;  // N
  int newton_iterations = 0;
  int multiplier_updates = 0;
  bool restarted = false;
  double restart_load_factor = 0.0;
  int steps_converged = 0;
  std::string tool_label;
  Vec3 tool_displacement = Vec3::Zero();               // mm
  Vec3 tool_force = Vec3::Zero();                      // N
  Vec3 max_displacement = Vec3::Zero();                // mm
  std::vector<std::pair<double, std::string>> frames;  // written frames (load factor, file)
  double seconds_build = 0.0, seconds_solve = 0.0, seconds_write = 0.0, seconds_total = 0.0;
  std::string grid_out;  // the grid file written, or empty
  // Viscous stabilisation (solver stabilise): dissipated energy to the last step (N mm),
  // damping factor c (N s/mm^4), its ratio to the strain energy there and the largest.
  bool stabilised = false;
  double stabilisation_energy = 0.0, stabilisation_damping = 0.0;
  double stabilisation_ratio = 0.0, stabilisation_max_ratio = 0.0;
  // Branch switches (solver branch_switch) of this run, one object each (recorder.cpp).
  nlohmann::json branch_switches = nlohmann::json::array();
};

// The "parameters" block.
nlohmann::json parameters_json(const FormingCase& spec, const Model& model);
// The whole summary.
nlohmann::json summary_json(const FormingCase& spec, const Model& model, const RunSummary& run);

}  // namespace sf::forming
