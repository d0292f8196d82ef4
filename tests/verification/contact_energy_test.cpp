// Energy balance of a dynamic run with friction (docs/forming.md "Contact checks"):
//
//   W_ext(t) = K(t) + U(t) - U(0) + D(t)
//
// W_ext the work the tool does on the bodies, K the kinetic energy 1/2 v^T M v, U the
// stored energy (elements and contact penalty), D the friction dissipation the contact
// reports (SurfaceContact::dissipated). The case: a 10 x 10 x 1 mm block at rest on a
// plane table that moves along x at 10 mm/s from t = 0; viscous inter-ply slip
// (c_f = 2e-4 N s/mm^3) drags the block along (time constant m / (c_f A) = 0.05 s) and
// sets it vibrating. The table sits 5e-4 mm below the block, where the rounded normal
// law (band 1e-3 mm) gives no pressure, and the viscous layer acts up to a 1 mm gap, so
// the drag does not depend on the contact pressure and nothing bounces. A symmetry plane
// y = 0 is the only support (the drag is along x). Trapezoidal integration in time
// (generalised-alpha with rho_inf = 1, one time step per output interval), and the
// dissipation is the trapezoidal sum the contact commits per interval; W_ext is summed as
// -sum 1/2 (F_k + F_k-1) . (d_k - d_k-1) over the tool's reaction F and displacement d.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/contact/surface_contact.hpp"
#include "forming/solve/mass.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

struct Balance {
  double work = 0.0, kinetic = 0.0, stored = 0.0, dissipated = 0.0;
  double worst = 0.0;  // largest |W - K - dU - D| / W over the steps
};

Balance run_balance(int steps) {
  const std::string text = R"(
materials:
  block: {neo_hookean: {E: 100, nu: 0.3}, density: 1.0e-5}
plies:
  - {name: b, size: [10, 10], thickness: 1, elements: [1, 1], material: block}
tools:
  - name: table
    plane: {point: [0, 0, -0.0005], normal: [0, 0, 1]}
    motion: {velocity: [10, 0, 0]}
contact:
  - {ply: b, face: bottom, tool: table, stiffness: 10, viscous: 2.0e-4, engage_gap: 1.0}
boundary_conditions:
  - symmetry: {ply: b, plane: y0}
solver: {analysis: dynamic, end_time: 0.1, steps: )" +
                           std::to_string(steps) + ", time_step: " + std::to_string(0.1 / steps) +
                           R"(, rho_inf: 1, tolerance: 1.0e-11}
)";
  const CaseCheck c = check_case_text(text, "contact_energy.yaml");
  EXPECT_TRUE(c.ok()) << c.located(0);
  Problem problem = build_problem(c.spec);
  const Model& model = problem.model;
  const auto& contact = dynamic_cast<const SurfaceContact&>(model.interaction(0));
  const linalg::SparseMatrix mass = mass_matrix(model, problem.density);

  struct Observer final : StepObserver {
    const Problem* p = nullptr;
    const SurfaceContact* c = nullptr;
    const linalg::SparseMatrix* mass = nullptr;
    VecX x_prev, v_prev;
    double t_prev = 0.0, u0 = 0.0;
    Vec3 f_prev = Vec3::Zero(), d_prev = Vec3::Zero();
    Balance b;
    void start(const VecX& x0) {
      x_prev = x0;
      v_prev = VecX::Zero(x0.size());
      const InteractionContext ctx{0.0, &v_prev, nullptr, 0.0};
      const ToolReaction r = c->reactions(x0, ctx).at(0);
      f_prev = r.force;
      d_prev = r.displacement;
      u0 = p->model.assemble(x0, ctx, false).energy;
    }
    StepAction on_step(const StepInfo& step, const SteppingState& s, const VecX&) override {
      const InteractionContext ctx{step.time, &s.v, &x_prev, t_prev};
      const ToolReaction r = c->reactions(s.x, ctx).at(0);
      b.work -= 0.5 * (r.force + f_prev).dot(r.displacement - d_prev);
      b.kinetic = kinetic_energy(*mass, s.v);
      b.stored = p->model.assemble(s.x, ctx, false).energy - u0;
      b.dissipated = c->dissipated();
      const double error = std::abs(b.work - b.kinetic - b.stored - b.dissipated);
      if (b.work > 0.0) b.worst = std::max(b.worst, error / b.work);
      f_prev = r.force;
      d_prev = r.displacement;
      x_prev = s.x;
      t_prev = step.time;
      return StepAction::kContinue;
    }
  } obs;
  obs.p = &problem;
  obs.c = &contact;
  obs.mass = &mass;
  const VecX x0 = model.reference_positions();
  obs.start(x0);
  SteppingState state{x0, VecX::Zero(x0.size()), 0.0};
  const SteppingReport rep = make_stepper(problem, stepper_settings(c.spec))->run(state, obs);
  EXPECT_EQ(rep.status, SteppingReport::Status::kFinished) << rep.message;
  return obs.b;
}

TEST(ContactEnergy, ToolWorkIsKineticPlusStoredPlusFrictionDissipation) {
  // Measured: 1.05e-4 (dt = 0.01 s), 6.9e-5 (0.005 s), 3.1e-5 (0.0025 s) of the work;
  // the residue falls with dt, but not at a steady order, so the bound is 2e-4.
  for (const int steps : {10, 20}) {
    const Balance b = run_balance(steps);
    std::printf(
        "energy balance, dt = %.4f s: W_tool = %.6g, K = %.6g, U - U0 = %.4g, D = %.6g N mm; largest |W - K - dU - D| "
        "/ W over the run %.2e\n",
        0.1 / steps, b.work, b.kinetic, b.stored, b.dissipated, b.worst);
    // Both the kinetic energy and the dissipation are a good part of the work.
    EXPECT_GT(b.kinetic, 0.2 * b.work);
    EXPECT_GT(b.dissipated, 0.2 * b.work);
    EXPECT_LT(b.worst, 2e-4);
  }
}

}  // namespace
}  // namespace sf::forming
