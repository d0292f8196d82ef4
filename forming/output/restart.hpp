#pragma once
// restart.json: the state of a run at its last written frame, written with every frame
// straight into the output folder (so it survives a run that is killed before its
// outputs are committed); `simform run --restart` continues from it.
//
//   format         "simform-restart-1"
//   case           the case file
//   fingerprint    what must not change for a restart: dofs, and every ply's name,
//                  origin, size, thickness, elements, angle and material
//   case_values    [key, value] of every value of the case file except `output`, and a
//                  checksum of each tool file (FormingCase::fingerprint); a restart
//                  with any of them changed is refused, naming what changed
//   step, load_factor  of the state
//   positions      n_dofs (mm); velocities n_dofs (mm/s, dynamic runs) or empty
//   multipliers    per body {p, T}: element pressures and fibre tensions (MPa)
//   history_rows   the rows of history.csv so far (without the header)
//   frames         [load factor, file name] of every frame written so far
//   parts          [load factor, file name, part] of the tool and contact parts so far
//   stabilisation  {damping (N s/mm^4), energy (N mm)}: stabilised runs (optional)
//   predictor_rate n_dofs (mm/s): load control with predictor: extrapolate, the rate the
//                  next step extrapolates with (optional; absent: none yet)
//   next_increment load control: the sub-step (fraction of a step) the next step starts with
//                  (optional; 0 or absent: a whole step)
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/vtk_xml.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

struct RestartState {
  int step = 0;
  double load_factor = 0.0;
  VecX positions;
  VecX velocities;  // dynamic runs (mm/s); empty for static ones
  std::string history_rows;
  std::vector<std::pair<double, std::string>> frames;
  std::vector<io::PvdDataSet> parts;  // tool and contact parts (part >= 1)
  // Stabilised runs (forming/solve/stabilisation.hpp): the damping factor in use
  // (N s/mm^4; 0: not yet calibrated) and the energy dissipated so far (N mm).
  double stabilisation_damping = 0.0;
  double stabilisation_energy = 0.0;
  // Load control with the extrapolating predictor: the last step's increment of positions
  // over its process time (n_dofs, mm/s; forming/solve/stepper.hpp SteppingState); empty: none.
  VecX predictor_rate;
  double next_increment = 0.0;  // load control: the next step's first sub-step, fraction of a step
};

// The multipliers come from `model`.
void write_restart(const std::string& path, const FormingCase& spec, const Model& model, const RestartState& s);
// Reads `path` and sets `model`'s multipliers from it. Throws sf::InputError when the
// file is missing or unreadable, was written for another model, or has the wrong size.
RestartState read_restart(const std::string& path, const FormingCase& spec, Model& model);

}  // namespace sf::forming
