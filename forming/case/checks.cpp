#include "forming/case/checks.hpp"

#include <algorithm>
#include <string>
#include <tuple>

namespace sf::forming {

void check_solver_rules(const FormingCase& spec, std::vector<CaseProblem>& problems) {
  const auto add = [&](ProblemKind kind, SourcePlace at, const std::string& message) {
    problems.push_back({kind, at, message, {}});
  };
  if (spec.solver.arc_length > 0.0) {
    const SourcePlace at = spec.solver.control_place;
    if (spec.solver.dynamic) add(ProblemKind::kUnsupported, at, "solver control arc_length: static analysis only");
    for (const CaseBoundary& bc : spec.boundaries)
      if (bc.kind == CaseBoundary::Kind::kDisplacement)
        add(ProblemKind::kUnsupported, bc.place,
            "solver control arc_length: prescribed displacements cannot follow the arc length "
            "(hold edges with clamp or symmetry; drive the case by loads)");
    for (const CaseLoad& l : spec.loads)
      if (l.ramp != Ramp::kLinear || !l.table.empty())
        add(ProblemKind::kUnsupported, l.place,
            "solver control arc_length: loads must be proportional to the load factor (ramp: linear, no time "
            "table)");
    for (const CaseMaterial& m : spec.materials)
      if (m.incompressible || m.inextensible)
        add(ProblemKind::kUnsupported, at,
            "solver control arc_length: material '" + m.name +
                "' is incompressible/inextensible; exact constraints need load control for now");
    if (spec.loads.empty()) add(ProblemKind::kMissing, at, "solver control arc_length: there is no load to scale");
  }
  if (spec.solver.stabilise_fraction > 0.0 || spec.solver.stabilise_damping > 0.0) {
    if (spec.solver.dynamic)
      add(ProblemKind::kUnsupported, spec.solver.stabilise_place,
          "solver stabilise: load control only (analysis: dynamic has inertia instead)");
    if (spec.solver.arc_length > 0.0)
      add(ProblemKind::kUnsupported, spec.solver.stabilise_place,
          "solver stabilise: load control only (not with control: arc_length)");
  }
  if (spec.solver.branch_switch_amplitude > 0.0) {
    if (spec.solver.dynamic)
      add(ProblemKind::kUnsupported, spec.solver.branch_switch_place,
          "solver branch_switch: load control only (analysis: dynamic follows the branch by inertia)");
    if (spec.solver.arc_length > 0.0)
      add(ProblemKind::kUnsupported, spec.solver.branch_switch_place,
          "solver branch_switch: load control only (not with control: arc_length)");
  }
  if (spec.solver.dynamic) {
    const SourcePlace at = spec.solver.analysis_place;
    for (const CaseMaterial& m : spec.materials) {
      if (!(m.density > 0.0))
        add(ProblemKind::kMissing, at,
            "solver analysis dynamic: material '" + m.name + "' has no density (t/mm^3, e.g. density: 1.5e-9)");
      if (m.incompressible || m.inextensible)
        add(ProblemKind::kUnsupported, at,
            "solver analysis dynamic: material '" + m.name +
                "' is incompressible/inextensible; exact constraints are quasi-static only for now");
    }
  }
}

std::vector<EdgeCondition> edge_conditions(const FormingCase& spec, int ply) {
  std::vector<EdgeCondition> out;
  for (const CaseBoundary& bc : spec.boundaries)
    if (bc.ply_index == ply) out.push_back({bc.kind, bc.side, bc.value, bc.ramp});
  return out;
}

// Plane strain across the width (y) of a ply: at every node of both layers, every
// parameter of y held at its reference value (u_y = 0: y = Y, dy/ds1 = 0, dy/ds2 = 1,
// cross 0) and the width derivatives of x and z (d/ds2 and d2/ds1ds2) held at 0. The
// values of x and z on the two width edges stay separate unknowns: with loads, contact
// and conditions uniform in y the problem is mirror-symmetric about the mid-width, so
// they move together (Newton keeps the symmetry to round-off), and any difference would
// cost shear strain across the width. A condition that moves y is a conflict.
namespace {
void add_plane_strain(const CasePly& ply, PlyConditions& c, std::vector<CaseProblem>& problems) {
  const PlyGrid grid{ply.n1, ply.n2};
  const Index n_nodes = 2 * grid.n_surface_nodes();
  std::vector<PrescribedParameter> added;
  const auto find = [&](Index node, int d, int coord) {
    return std::find_if(c.parameters.begin(), c.parameters.end(),
                        [&](const PrescribedParameter& p) { return p.node == node && p.d == d && p.coord == coord; });
  };
  bool reported = false;
  for (Index node = 0; node < n_nodes; ++node)
    for (int d = 0; d < 4; ++d)
      for (int coord = 0; coord < 3; ++coord) {
        if (coord != 1 && d < 2) continue;
        const auto it = find(node, d, coord);
        if (it == c.parameters.end()) {
          added.push_back({node, d, coord, 0.0, Ramp::kLinear, -1});
        } else if (it->displacement != 0.0 && !reported) {
          problems.push_back(
              {ProblemKind::kConflict,
               ply.place,
               "ply '" + ply.name + "' is plane strain (u_y = 0 across its width), but a boundary condition moves y",
               {}});
          reported = true;
        }
      }
  c.parameters.insert(c.parameters.end(), added.begin(), added.end());
  std::sort(c.parameters.begin(), c.parameters.end(), [](const PrescribedParameter& a, const PrescribedParameter& b) {
    return std::tie(a.node, a.d, a.coord) < std::tie(b.node, b.d, b.coord);
  });
}
}  // namespace

std::vector<PlyConditions> discretise_boundary_conditions(const FormingCase& spec, std::vector<CaseProblem>& problems) {
  std::vector<PlyConditions> out;
  for (std::size_t p = 0; p < spec.plies.size(); ++p) {
    const CasePly& ply = spec.plies[p];
    std::vector<const CaseBoundary*> of_ply;  // case condition of each edge condition
    for (const CaseBoundary& bc : spec.boundaries)
      if (bc.ply_index == static_cast<int>(p)) of_ply.push_back(&bc);
    out.push_back(discretise_conditions(PlyGrid{ply.n1, ply.n2}, edge_conditions(spec, static_cast<int>(p))));
    for (const ConditionConflict& c : out.back().conflicts) {
      const CaseBoundary& later = *of_ply[static_cast<std::size_t>(c.later)];
      const CaseBoundary& earlier = *of_ply[static_cast<std::size_t>(c.earlier)];
      problems.push_back({ProblemKind::kConflict,
                          later.place,
                          to_string(later.kind) + " on " + to_string(later.side) + " of ply '" + ply.name +
                              "' prescribes some of the same dofs as the " + to_string(earlier.kind) + " on " +
                              to_string(earlier.side) + " (line " + std::to_string(earlier.place.line) +
                              ") differently",
                          {}});
    }
    if (ply.plane_strain) add_plane_strain(ply, out.back(), problems);
  }
  return out;
}

void check_boundary_conditions(const FormingCase& spec, std::vector<CaseProblem>& problems) {
  bool any = false;
  for (const PlyConditions& c : discretise_boundary_conditions(spec, problems)) any = any || !c.parameters.empty();
  if (!any)
    problems.push_back({ProblemKind::kNothingHeld,
                        {1, 1},
                        "boundary_conditions: nothing is held (the plies could move as rigid bodies)",
                        {}});
}

}  // namespace sf::forming
