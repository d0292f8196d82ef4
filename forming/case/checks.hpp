#pragma once
// Cross-field rules of a case, checked after every section has been read (what one
// section allows depends on another). Each problem has its kind and the place of the
// key it concerns:
//   control: arc_length  static analysis only; edges held by clamp or symmetry (no
//                        prescribed displacement); loads proportional (linear ramps);
//                        no exact constraints; at least one load;
//   analysis: dynamic    every material has a density; no exact constraints;
//   boundary conditions  no two prescribe a dof differently (reported at the later
//                        one); at least one dof of some ply is held.
#include <vector>

#include "forming/case/problems.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/prescriptions.hpp"

namespace sf::forming {

// The arc-length and dynamic rules.
void check_solver_rules(const FormingCase& spec, std::vector<CaseProblem>& problems);

// The boundary conditions of ply `ply` as edge conditions of the model
// (forming/model/prescriptions.hpp), in case order.
std::vector<EdgeCondition> edge_conditions(const FormingCase& spec, int ply);

// Discretises the boundary conditions of every ply (needs valid plies); appends a
// kConflict problem for each pair that prescribes a dof differently. One entry per ply.
std::vector<PlyConditions> discretise_boundary_conditions(const FormingCase& spec, std::vector<CaseProblem>& problems);

// discretise_boundary_conditions() plus the kNothingHeld rule.
void check_boundary_conditions(const FormingCase& spec, std::vector<CaseProblem>& problems);

}  // namespace sf::forming
