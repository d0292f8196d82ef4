#pragma once
// From a checked case (forming/case/reader.hpp) to what the solver works on, built once:
//
//   build_model          one body per ply, in case order (body b = ply b): a brick mesh
//                        on the ply's rectangle, its material (TI fibre direction from
//                        the layup angle) and exact constraints with their penalties
//                        (100 times the law's own volumetric / fibre stiffness);
//   build_loads          the loads as load sets with their ramps (pressure on every face
//                        of a ply side, gravity rho g on every ply, edge forces spread
//                        over the side faces, point forces on value dofs);
//   build_prescriptions  the boundary conditions as prescribed dofs
//                        (forming/model/prescriptions.hpp);
//   add_contacts         one interaction per contact pair (forming/contact/): a
//                        ToolContact against a tool, a BodyContact against a ply, the
//                        slave being the pair's first ply (all faces of its side);
//   build_problem        all of these and the densities (forming/model/problem.hpp);
//   stepper_settings     the solver section as settings of the chosen stepper
//                        (forming/solve/stepper.hpp).
#include "forming/case/schema.hpp"
#include "forming/model/loads.hpp"
#include "forming/model/model.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/model/problem.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {

Model build_model(const FormingCase& spec);
RampedLoads build_loads(const FormingCase& spec, const Model& model);
// Throws sf::InputError at the later of two conditions that prescribe a dof differently
// (check_case_*() reports it first).
Prescriptions build_prescriptions(const FormingCase& spec, const Model& model);
void add_contacts(const FormingCase& spec, Model& model);
Problem build_problem(const FormingCase& spec);

// Throws sf::InputError naming the option if a setting is out of range.
StepperSettings stepper_settings(const FormingCase& spec);

}  // namespace sf::forming
