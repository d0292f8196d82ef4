#pragma once
// Interactions: forces that act between bodies, or between a body and something outside
// the model (a rigid tool), rather than inside one body's elements. Penalty contact
// ply-ply and ply-tool, viscous inter-ply friction, tools driven by time functions and
// springs are interactions (the first one: forming/model/node_spring.hpp). The Model
// owns them and adds each one's contribution to every assembly
// (forming/model/model.hpp), so the static, dynamic and arc-length solvers need no
// change when one is added.
//
// What an interaction sees (InteractionContext + the positions):
//   x         current positions of all bodies, n_dofs (mm), Model numbering;
//   velocity  dx/dt, n_dofs (mm/s), where the solver has one (dynamic runs: at the
//             generalised-alpha point), else null;
//   time      s in dynamic runs (t_{n+1-af}); 0 in quasi-static solves for now (a tool
//             moving with the process in a quasi-static run will need the stepper to
//             pass the step's load factor down: the place for it is this field).
// What it adds (InteractionSums, added to, never overwritten):
//   energy    its stored energy, N mm (0 for a dissipative interaction);
//   force     its force on the dofs with the sign of an internal force: the gradient of
//             its energy, i.e. the force the bodies exert on it; the residual is
//             r = f_elements + f_interactions - f_ext (N, n_dofs);
//   stiffness d force / dx (N/mm) when asked for (non-null), into the model's triplets;
//   damping   d force / dv (N s/mm) when asked for (non-null: the solver has velocities).
// A state the interaction cannot evaluate (e.g. a contact search that fails) is a
// numerical outcome: set `ok` false and a message, as an inverted element does.
//
// Tools report their reaction (the force the bodies exert on the tool, N) through
// reactions(), one entry per tool, for history.csv.
//
// Units: mm, N, s.

#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::forming {

// Time and velocities an assembly is evaluated with (positions are passed separately).
struct InteractionContext {
  double time = 0.0;               // s (dynamic); 0 in quasi-static solves
  const VecX* velocity = nullptr;  // n_dofs, mm/s; null where the solver has none
};

// Running sums of one assembly that interactions add to.
struct InteractionSums {
  bool ok = true;
  std::string message;                             // why the state is inadmissible
  double energy = 0.0;                             // N mm
  VecX force;                                      // n_dofs, N
  linalg::TripletAssembler* stiffness = nullptr;   // d force / dx, or null: not wanted
  linalg::TripletAssembler* damping = nullptr;     // d force / dv, or null: not wanted
};

// Reaction on a tool: the resultant force the bodies exert on it (N).
struct ToolReaction {
  std::string tool;
  Vec3 force = Vec3::Zero();
};

class Interaction {
 public:
  virtual ~Interaction() = default;
  virtual std::string name() const = 0;
  // Adds energy, force and (where asked for) stiffness and damping at positions x.
  virtual void add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                      InteractionSums& sums) const = 0;
  // False when the stiffness or damping it adds is not symmetric (friction): the
  // solvers then factorise with an unsymmetric solver.
  virtual bool symmetric() const { return true; }
  // True when its force depends on the velocities.
  virtual bool needs_velocity() const { return false; }
  // Reactions on the tools it drives at positions x (none for a body-body interaction).
  virtual std::vector<ToolReaction> reactions(const Eigen::Ref<const VecX>& x,
                                              const InteractionContext& context) const {
    (void)x;
    (void)context;
    return {};
  }
};

}  // namespace sf::forming
