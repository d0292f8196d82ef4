#pragma once
// Automatic (viscous) stabilisation of a quasi-static load-controlled run, after the
// volume-proportional damping commercial implicit codes add to unstable static problems
// (Abaqus/Standard's automatic stabilisation, ANSYS' STABILIZE): a viscous force
//
//   F_v = c M* v,   v = (x - x_prev) / (t - t_prev),
//
// is added to the equilibrium equations, with M* the consistent mass matrix of the
// model at unit density (forming/solve/mass.hpp with rho = 1 per body: M* in mm^3),
// x_prev the last converged (sub-)step's state at process time t_prev, and c the damping
// factor (N s/mm^4: force per unit volume per unit velocity). Its tangent
// dF_v/dx = (c / dt) M* is symmetric positive semi-definite; added to K it makes the
// Newton matrix definite where a ply buckles (negative K along the buckle) once
// c / dt exceeds the magnitude of the negative curvature per unit M*. A step cut back
// to a smaller dt is damped more strongly. When x stands still (the state at rest,
// equilibrium reached) F_v vanishes: converged states of a slow process are the static
// ones up to the dissipated fraction, which the run reports.
//
// The factor c is either given (`damping`) or calibrated from the first output step
// (`fraction`, Abaqus' default 2e-4): that step is solved without stabilisation and
//
//   c = fraction * dE_s * dt / (dx^T M* dx),
//
// dE_s the step's increase of the elements' strain energy (N mm), dx its displacement
// increment (mm) over its process time dt (s), so that the energy a step like the first
// dissipates, c dx^T M* dx / dt, is `fraction` of the strain energy it stores (the
// extrapolated strain energy of Abaqus' definition, for steps of equal size). When the
// first step fails unstabilised, its last converged sub-step calibrates c (the same
// formula over the part of the step reached) and the step is solved again, stabilised,
// from its start (forming/solve/stepper.cpp).
//
// The dissipated energy of a sub-step from x_prev to x over dt is
//   W_v = F_v . (x - x_prev) = c (x - x_prev)^T M* (x - x_prev) / dt  (N mm),
// summed over the converged sub-steps (history.csv stabilisation_energy); its ratio
// to the strain energy says how far the result is from quasi-static.
//
// Active only where the context has rates from a previous state at an earlier time
// (load control with a process clock); the arc-length and dynamic solvers see nothing.
// Units: mm, N, s.
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// The case's choice (forming/case/schema.hpp CaseSolver::stabilise).
struct StabiliseOptions {
  double fraction = 0.0;   // > 0: calibrate c from the first step (dimensionless)
  double damping = 0.0;    // > 0: this c from the start, N s/mm^4
  double warn_ratio = 0.05;  // dissipated / strain energy above which the run warns
  double start_energy = 0.0;  // N mm dissipated before this run (a restart)
  bool active() const { return fraction > 0.0 || damping > 0.0; }
  // Throws sf::InputError naming "solver stabilise <field>".
  void validate() const;
};

class ViscousStabilisation final : public Interaction {
 public:
  // Builds M* of `model` (unit density). Throws sf::InputError for an inverted brick.
  explicit ViscousStabilisation(const Model& model, double damping = 0.0);

  std::string name() const override { return "stabilisation"; }
  void add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
              InteractionSums& sums) const override;
  // Its rates come from the previous state (context.previous), never from a solver's
  // velocities, so it adds no damping matrix: needs_velocity() stays false.

  double damping() const { return c_; }  // N s/mm^4
  // Throws sf::InputError for a negative or non-finite value.
  void set_damping(double c);
  // d^T M* d (mm^5).
  double mass_norm(const Eigen::Ref<const VecX>& d) const;
  // The energy dissipated from `from` to `to` over dt (s) at the present c: c |to - from|^2_M* / dt, N mm.
  double dissipation(const Eigen::Ref<const VecX>& from, const Eigen::Ref<const VecX>& to, double dt) const;
  const linalg::SparseMatrix& mass() const { return mass_; }

 private:
  linalg::SparseMatrix mass_;  // M*, mm^3
  std::vector<Index> rows_, cols_;
  std::vector<double> values_;  // M*'s entries, for the tangent's triplets
  double c_ = 0.0;
};

// c from a calibrating increment: fraction * strain_energy_increase * dt / (dx^T M* dx);
// 0 when the increment stored no energy or did not move (no calibration possible).
double calibrated_damping(const ViscousStabilisation& s, double fraction, double strain_energy_increase,
                          const Eigen::Ref<const VecX>& dx, double dt);

}  // namespace sf::forming
