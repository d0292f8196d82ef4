#pragma once
// Branch switching at a bifurcation of quasi-static load control (the case key
// `solver: {branch_switch: {amplitude: A}}`, docs/forming.md "Branch switching").
//
// Load control follows the path it starts on. Where a symmetric (fundamental) path
// bifurcates - a ply in compression buckles away from its neighbours - a real eigenvalue
// of the tangent passes zero and the determinant changes sign; the path goes on as an
// unstable equilibrium, and Newton either stays on it or stalls near it. The standard
// remedy (Riks with an eigenmode imperfection, Abaqus *IMPERFECTION; Wriggers, Nonlinear
// Finite Element Methods, ch. 7) adds a small imperfection along the critical mode so that
// the next solve falls onto the buckled (stable) branch. Here, during the run:
//   - after a converged step whose tangent has det K < 0 where the last checked state's
//     had det K > 0 (one real eigenvalue newly below zero), the state is moved along the
//     tangent's eigenmode nearest zero by A (mm, the largest nodal displacement of the
//     mode), with the sign of lower stored energy, and the next step starts from there;
//     If the next step's end is still unstable (Newton went back to the unstable path: the
//     imperfection was too small to leave its basin), the next switch doubles the
//     amplitude, up to 8 A;
//   - a step that fails is tried again from its last converged sub-step moved the same
//     way along that state's nearest-zero mode (at most twice a step).
// The nearest-zero mode is found by inverse iteration on the factorised tangent
// (nearest_eigenvalue, also SF_NEWTON_TRACE's). K is unsymmetric in the forming cases
// (viscous inter-ply slip), so it is the mode of K itself over the step's rates.
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/prescriptions.hpp"

namespace sf::forming {

class Model;
class TangentSolver;
class TangentWorkspace;

struct BranchSwitchOptions {
  double amplitude = 0.0;  // mm: largest nodal displacement of the imperfection; 0: off
  int inverse_steps = 30;  // inverse-iteration solves for the mode
  // A failed step: its solve gives up after this many failed sub-steps
  // (StaticOptions::give_up_after) and is tried again from its last converged sub-step
  // moved along the mode, at most `retries` times; the last try cuts back to
  // min_increment. A retry that starts where the last one did (no progress) doubles
  // the amplitude, up to 8 A. give_up_after 0: every try cuts back to min_increment.
  int give_up_after = 4;
  int retries = 4;
  // The last retry runs with this many times the stabilisation damping (a snap no switch
  // passes is then damped through, dissipating more: the run warns); 1: not raised.
  double last_retry_damping = 1.0;
  bool active() const { return amplitude > 0.0; }
  // Throws sf::InputError naming "solver branch_switch <field>".
  void validate() const;
};

// The eigenvalue of the factorised K (solver holds its factorisation) nearest zero by
// `steps` steps of inverse iteration from a fixed start, as a fraction of max |K_ii|;
// `mode` (unit, K's unknowns) its eigenvector, `spread` the eigen-residual
// |K^-1 x - x / lambda| / |K^-1 x| of the last step (small: a real eigenvalue; near 1: a
// complex pair or close eigenvalues, a rough estimate). NaN when a solve failed.
double nearest_eigenvalue(TangentSolver& solver, const linalg::SparseMatrix& k, double& spread, VecX& mode,
                          int steps = 8);

// Where a mode v (all dofs) is largest and how it divides over the plies (bodies).
struct ModePlace {
  int ply = 0;                   // 1-based body of the largest entry
  Index node = 0;                // its node in that body
  double x = 0.0, z = 0.0;       // the node's position, mm
  char coordinate = 'x';         // of the largest entry
  bool derivative = false;       // the largest entry is a derivative dof
  std::vector<double> shares;    // each ply's share of |v|^2, %
};
ModePlace mode_place(const Model& model, const VecX& v, const VecX& x);
// "largest at ply 2 node 5 (x 3.9, z -1.2) z; ply shares % 3 87 6 4" (SF_NEWTON_TRACE).
std::string describe(const ModePlace& place);

// The tangent of a converged state and its mode nearest zero.
struct TangentMode {
  bool ok = false;
  std::string message;      // why not ok
  int determinant_sign = 0; // +1, -1; 0 when the solver does not tell
  int negative_pivots = -1; // symmetric LDL^T only, else -1
  double eigenvalue = 0.0;  // nearest zero, / max |K_ii|
  double spread = 1.0;
  VecX mode;                // n_dofs, zero on prescribed and unused dofs, max |position entry| = 1
  ModePlace place;
};

// K_ff of `model` at x (free: used dofs not in `prescribed`) with the interactions' rates
// of `context`, factorised in `workspace` (its own: kept apart from the Newton solver's),
// and its nearest-zero mode.
TangentMode tangent_mode(const Model& model, const VecX& x, const std::vector<PrescribedDof>& prescribed,
                         const InteractionContext& context, const linalg::SparseMatrix* load_tangent,
                         TangentWorkspace& workspace, int inverse_steps);

// x moved by amplitude (mm) along the mode, with the sign whose state stores less energy
// (Model::assemble's energy under `context`; + when equal or either is inadmissible, and
// the other side when only that one is admissible). `sign` gets the sign used; an empty
// vector when neither side is admissible.
VecX perturbed(const Model& model, const VecX& x, const VecX& mode, double amplitude,
               const InteractionContext& context, int& sign);

}  // namespace sf::forming
