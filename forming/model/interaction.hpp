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
//   time      s: in dynamic runs t_{n+1-af}; in quasi-static load steps the process time
//             lambda * process_time (forming/solve/static_solver.hpp ProcessClock; a tool
//             moves with it); 0 where the solver has no clock (arc length);
//   velocity  dx/dt, n_dofs (mm/s), where the solver has one (dynamic runs: at the
//             generalised-alpha point), else null;
//   previous, previous_time  quasi-static runs with a process time: the last converged
//             state and its time, so rates are finite differences over the step,
//               v = (x - previous) / (time - previous_time)   where time > previous_time
//             (rates() below); a velocity-dependent interaction (friction) then adds the
//             1/dt of that difference to its stiffness.
// What it adds (InteractionSums, added to, never overwritten):
//   energy    its stored energy, N mm (0 for a dissipative interaction);
//   force     its force on the dofs with the sign of an internal force: the gradient of
//             its energy, i.e. the force the bodies exert on it; the residual is
//             r = f_elements + f_interactions - f_ext (N, n_dofs);
//   stiffness d force / dx (N/mm) when asked for (non-null), into the model's triplets
//             (or straight into `pattern` where the assembly gives one);
//   damping   d force / dv (N s/mm) when asked for (non-null: the solver has velocities).
// A state the interaction cannot evaluate (e.g. a contact search that fails) is a
// numerical outcome: set `ok` false and a message, as an inverted element does.
//
// State. An interaction may carry state the solvers update between solves:
//   commit()              after every converged step (the steppers, forming/solve/
//                         stepper.hpp): history such as accumulated slip and dissipation,
//                         with the step's start state in context.previous;
//   update_multipliers()  augmented Lagrangian: after a converged solve, the steppers ask
//                         every interaction to update its multipliers from the state and
//                         repeat the solve until each reports its constraint met.
// Tools report their reaction (the force the bodies exert on the tool, N) and their
// displacement through reactions(), one entry per tool, for history.csv.
//
// Units: mm, N, s.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/pattern_assembler.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::forming {

// Time and rates an assembly is evaluated with (positions are passed separately).
struct InteractionContext {
  double time = 0.0;               // s
  const VecX* velocity = nullptr;  // n_dofs, mm/s; null where the solver has none
  const VecX* previous = nullptr;  // n_dofs, mm: last converged state (quasi-static), or null
  double previous_time = 0.0;      // s, of `previous`
  // True when rates can be formed: velocities given, or a previous state at an earlier time.
  bool has_rates() const { return velocity != nullptr || (previous != nullptr && time > previous_time); }
};

// Running sums of one assembly that interactions add to.
struct InteractionSums {
  bool ok = true;
  std::string message;                            // why the state is inadmissible
  double energy = 0.0;                            // N mm
  VecX force;                                     // n_dofs, N
  linalg::TripletAssembler* stiffness = nullptr;  // d force / dx, or null: not wanted
  linalg::TripletAssembler* damping = nullptr;    // d force / dv, or null: not wanted
  // Where set (with stiffness), an interaction may add its stiffness straight into this
  // kept pattern (PatternAssembler::add_block: same entries, same order as through the
  // triplets) instead of into `stiffness`, counting the entries in pattern_entries.
  linalg::PatternAssembler* pattern = nullptr;
  long pattern_entries = 0;
};

// Reaction on a tool: the resultant force the bodies exert on it (N) and where the tool
// is (its displacement from rest, mm).
struct ToolReaction {
  std::string tool;
  Vec3 force = Vec3::Zero();
  Vec3 displacement = Vec3::Zero();
};

// What an augmented-Lagrangian update found (before updating).
struct MultiplierUpdate {
  bool converged = true;   // the constraint was met to its tolerance: nothing was updated
  double violation = 0.0;  // e.g. the largest penetration, mm
  double tolerance = 0.0;  // the same units
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
  // The blocks (rows x columns, global dofs) its stiffness may fill at states near x, for
  // the tangent's pattern: contact gives every slave face and partner face within its
  // search distance, touching or not, so a pair closing later inside that band finds its
  // entries laid out and needs no new symbolic analysis (Model::assemble_into asks when
  // the pattern has to grow anyway). Default: none.
  virtual void pattern_blocks(
      const Eigen::Ref<const VecX>& x, const InteractionContext& context,
      const std::function<void(const std::vector<Index>& rows, const std::vector<Index>& cols)>& block) const {
    (void)x;
    (void)context;
    (void)block;
  }
  // Reactions on the tools it drives at positions x (none for a body-body interaction).
  virtual std::vector<ToolReaction> reactions(const Eigen::Ref<const VecX>& x,
                                              const InteractionContext& context) const {
    (void)x;
    (void)context;
    return {};
  }
  // After a converged step reaching x (context.previous: the step's start, if known).
  virtual void commit(const Eigen::Ref<const VecX>& x, const InteractionContext& context) {
    (void)x;
    (void)context;
  }
  // Augmented Lagrangian: measure the constraint at the converged state x; when it is not
  // met, update the multipliers (the caller then solves again). Default: nothing to do.
  virtual MultiplierUpdate update_multipliers(const Eigen::Ref<const VecX>& x, const InteractionContext& context) {
    (void)x;
    (void)context;
    return {};
  }
};

}  // namespace sf::forming
