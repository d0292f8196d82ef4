// Contact against closed forms (forming/contact/; docs/forming.md "Contact checks"),
// each case a case file run through the whole chain (reader, build, load stepper):
//   * patch test: two blocks under a uniform pressure p: with matching meshes every
//     contact point of the interface carries p (to round-off); with non-matching meshes
//     (2 x 2 against 3 x 3 elements) the one-pass point-to-surface scheme does NOT pass
//     exactly (the master's piecewise cubics are not integrated exactly by the slave's
//     Gauss points, as known for one-pass node/Gauss-point-to-surface contact): the
//     measured spread, 6 % with 6 x 6 points, is held as a bound so it cannot grow;
//   * sliding block: a stiff block pressed onto a plane tool that slides under it at
//     speed v: tool force F_x = c_f v A (viscous; the block's own slow Poisson spreading
//     under the rising pressure is the error) and F_x = mu N with N the tool's normal
//     force (Coulomb, v >> the stick velocity);
//   * ply pull-out: the middle of three plies (width w, overlap L0) pulled out at speed v
//     between two held plies: F = 2 w (L0 - d) c_f v at pull-out distance d, and each
//     interface carries half of it; with the molten fibre law the rig's platen pressure
//     holds the plies together (without it half of each interface opened: issue 12).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/contact/surface_contact.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

// Keeps every converged state and the reactions of each step.
struct Keep final : StepObserver {
  std::vector<VecX> x, reactions;
  std::vector<double> time;
  StepAction on_step(const StepInfo& step, const SteppingState& state, const VecX& r) override {
    x.push_back(state.x);
    reactions.push_back(r);
    time.push_back(step.time);
    return StepAction::kContinue;
  }
};

struct CaseRun {
  FormingCase spec;
  Problem problem;
  Keep steps;
  VecX x0;
};

// Reads `text`, builds and runs it to the end (asserting convergence).
void run(const std::string& text, CaseRun& r) {
  const CaseCheck c = check_case_text(text, "contact_verification.yaml");
  ASSERT_TRUE(c.ok()) << c.located(0);
  r.spec = c.spec;
  r.problem = build_problem(r.spec);
  r.x0 = r.problem.model.reference_positions();
  SteppingState state{r.x0, VecX::Zero(r.x0.size()), 0.0};
  const std::unique_ptr<Stepper> stepper = make_stepper(r.problem, stepper_settings(r.spec));
  const SteppingReport rep = stepper->run(state, r.steps);
  ASSERT_EQ(rep.status, SteppingReport::Status::kFinished) << rep.message;
}

// The context of step k (1-based index into the kept steps, 0 = reference).
InteractionContext context_of(const CaseRun& r, std::size_t k) {
  const VecX* prev = k >= 2 ? &r.steps.x[k - 2] : &r.x0;
  const double t_prev = k >= 2 ? r.steps.time[k - 2] : 0.0;
  return InteractionContext{r.steps.time[k - 1], nullptr, prev, t_prev};
}

// Largest relative deviation of the interface pressure from p, upper block meshed n x n,
// over the contact points of every pass.
double patch_error(int n, int points, bool two_pass = false) {
  const double p = 0.05;  // MPa
  CaseRun r;
  run(R"(
materials:
  soft: {neo_hookean: {E: 10, nu: 0.3}}
plies:
  - {name: lower, size: [10, 10], thickness: 1, elements: [2, 2], material: soft}
  - {name: upper, origin: [0, 0, 1], size: [10, 10], thickness: 1, elements: [)" +
          std::to_string(n) + ", " + std::to_string(n) + R"(], material: soft}
contact:
  - {ply: lower, face: top, with: upper, with_face: bottom, stiffness: 1000, points: )" +
          std::to_string(points) + (two_pass ? ", two_pass: true" : "") + R"(}
boundary_conditions:
  - symmetry: {ply: lower, plane: bottom}
  - symmetry: {ply: lower, plane: x0}
  - symmetry: {ply: lower, plane: y0}
  - symmetry: {ply: upper, plane: x0}
  - symmetry: {ply: upper, plane: y0}
loads:
  - pressure: {ply: upper, face: top, value: 0.05, follower: false}
solver: {steps: 1, tolerance: 1.0e-10}
)",
      r);
  double worst = 0.0;
  int count = 0;
  for (int i = 0; i < r.problem.model.n_interactions(); ++i) {
    const auto& c = dynamic_cast<const SurfaceContact&>(r.problem.model.interaction(i));
    for (const ContactPointRecord& rec : c.sample(r.steps.x.back(), context_of(r, 1))) {
      EXPECT_TRUE(rec.partner);
      worst = std::max(worst, std::abs(rec.pressure - p) / p);
      ++count;
    }
  }
  EXPECT_EQ(count, (two_pass ? 4 + n * n : 4) * points * points);
  return worst;
}

TEST(ContactPatch, UniformPressureCrossesTheInterface) {
  const double matching = patch_error(2, 6);
  const double non_matching = patch_error(3, 6);
  EXPECT_LT(matching, 1e-6);
  EXPECT_LT(non_matching, 0.07);
  std::printf("patch test: largest relative pressure error %.2e (matching 2 x 2 meshes), %.2e (2 x 2 against 3 x 3)\n",
              matching, non_matching);
  for (const int points : {8, 12}) {
    const double e = patch_error(3, points);
    std::printf("patch test, one pass, %d x %d points a face: %.2e (2 x 2 against 3 x 3)\n", points, points, e);
  }
}

TEST(ContactPatch, TwoHalfPassesTransmitTheUniformPressureAcrossNonMatchingMeshes) {
  const double matching = patch_error(2, 6, true);
  const double non_matching = patch_error(3, 6, true);
  std::printf(
      "patch test, two half-passes: largest relative pressure error %.2e (matching), %.2e (2 x 2 against 3 x 3)\n",
      matching, non_matching);
  EXPECT_LT(matching, 1e-6);
  EXPECT_LT(non_matching, 1e-6);
}

// A 10 x 10 x 1 block on a plane tool sliding at v = 2 mm/s along x under the block,
// whose x0 edge is clamped; `loads` on it. Returns the tool's force at the end.
Vec3 sliding_block_force(const std::string& law, const std::string& loads, CaseRun& r, double speed = 2.0,
                         int steps = 3) {
  run(R"(
materials:
  block: {neo_hookean: {E: 10000, nu: 0.3}}
plies:
  - {name: b, size: [10, 10], thickness: 1, elements: [2, 2], material: block}
tools:
  - name: table
    plane: {point: [0, 0, 0], normal: [0, 0, 1]}
    motion: {velocity: [)" +
          std::to_string(speed) + R"(, 0, 0]}
contact:
  - {ply: b, face: bottom, tool: table, stiffness: 1000, )" +
          law + R"(}
boundary_conditions:
  - clamp: {ply: b, edge: x0}
)" + loads +
          R"(
solver: {steps: )" + std::to_string(steps) +
          R"(, process_time: 0.3, tolerance: 1.0e-10}
)",
      r);
  const auto& c = dynamic_cast<const SurfaceContact&>(r.problem.model.interaction(0));
  const std::vector<ToolReaction> tr = c.reactions(r.steps.x.back(), context_of(r, r.steps.x.size()));
  return tr.at(0).force;
}

TEST(SlidingBlock, ViscousForceIsCfVA) {
  CaseRun r;
  const double F = sliding_block_force("viscous: 0.02", "loads:\n  - pressure: {ply: b, face: top, value: 0.2}", r).x();
  const double expected = 0.02 * 2.0 * 100.0;  // c_f v A, N
  // The tool moves +x, the block's drag on it points -x.
  EXPECT_NEAR(-F, expected, 1e-4 * expected);
  std::printf("sliding block, viscous: F = %.8g N, c_f v A = %.8g N, relative error %.2e\n", -F, expected,
              std::abs(-F - expected) / expected);
}

TEST(SlidingBlock, CoulombForceIsMuN) {
  CaseRun r;
  const Vec3 F = sliding_block_force("coulomb: 0.3, stick_velocity: 0.002",
                                     "loads:\n  - pressure: {ply: b, face: top, value: 0.2}", r);
  // N: the tool's normal force (the clamped edge carries part of the load). Regularised:
  // mu v / sqrt(v^2 + eps^2) = mu (1 - 5e-7) at v / eps = 1000.
  const double N = -F.z();
  EXPECT_GT(N, 0.5 * 0.2 * 100.0);
  EXPECT_NEAR(-F.x(), 0.3 * N, 1e-5 * 0.3 * N);
  std::printf("sliding block, Coulomb: F = %.8g N, mu N = %.8g N (N = %.6g N), relative error %.2e\n", -F.x(), 0.3 * N,
              N, std::abs(-F.x() - 0.3 * N) / (0.3 * N));
}

// Coulomb regularised by slip distance (stick_slip, contact_law.hpp): sliding, the drag is
// mu N exactly (the return map's slip branch); sticking (the table creeps 3e-4 mm under
// the block, d = 1e-3 mm), the drag is the elastic stick's and the same whatever the
// number of steps (rate- and step-independent). The velocity form instead restarts each
// step from no traction, so its drag depends on the step: printed for comparison.
TEST(SlidingBlock, CoulombBySlipDistanceIsMuNSlidingAndStepIndependentSticking) {
  const std::string load = "loads:\n  - pressure: {ply: b, face: top, value: 0.2}";
  CaseRun r;
  const Vec3 F = sliding_block_force("coulomb: 0.3, stick_slip: 0.001", load, r);
  const double N = -F.z();
  EXPECT_NEAR(-F.x(), 0.3 * N, 1e-9 * 0.3 * N);
  std::printf("sliding block, Coulomb by slip distance: F = %.10g N, mu N = %.10g N, relative error %.2e\n", -F.x(),
              0.3 * N, std::abs(-F.x() - 0.3 * N) / (0.3 * N));
  double stick[2], velocity[2];
  const int steps[2] = {3, 7};
  for (int i = 0; i < 2; ++i) {
    CaseRun a, b;
    stick[i] = -sliding_block_force("coulomb: 0.3, stick_slip: 0.001", load, a, 0.001, steps[i]).x();
    velocity[i] = -sliding_block_force("coulomb: 0.3, stick_velocity: 0.0033", load, b, 0.001, steps[i]).x();
  }
  // Sticking: a fraction of mu N (the slip 3e-4 mm against d = 1e-3 mm, less the block's
  // own shear), the same in 3 and 7 steps.
  EXPECT_GT(stick[0], 0.1 * 0.3 * N);
  EXPECT_LT(stick[0], 0.35 * 0.3 * N);
  EXPECT_NEAR(stick[1], stick[0], 1e-6 * stick[0]);
  std::printf("creeping table (3e-4 mm): stick_slip 1e-3 mm: %.8g N (3 steps), %.8g N (7 steps); stick_velocity "
              "3.3e-3 mm/s: %.8g N, %.8g N\n",
              stick[0], stick[1], velocity[0], velocity[1]);
}

TEST(AugmentedLagrangian, DrivesThePenetrationUnderItsTolerance) {
  // A block pressed by p = 0.2 MPa onto a table with a soft penalty S_n = 10 N/mm^3:
  // the penalty alone leaves p / S_n = 0.02 mm; Uzawa updates bring it under 1e-4 mm.
  const auto max_penetration = [](const std::string& extra, int* updates) {
    CaseRun r;
    run(R"(
materials:
  block: {neo_hookean: {E: 100, nu: 0.3}}
plies:
  - {name: b, size: [10, 10], thickness: 1, elements: [2, 2], material: block}
tools:
  - name: table
    plane: {point: [0, 0, 0], normal: [0, 0, 1]}
contact:
  - {ply: b, face: bottom, tool: table, stiffness: 10)" +
            extra + R"(}
boundary_conditions:
  - symmetry: {ply: b, plane: x0}
  - symmetry: {ply: b, plane: y0}
loads:
  - pressure: {ply: b, face: top, value: 0.2}
solver: {steps: 1, tolerance: 1.0e-10}
)",
        r);
    const auto& c = dynamic_cast<const SurfaceContact&>(r.problem.model.interaction(0));
    double worst = 0.0;
    for (const ContactPointRecord& rec : c.sample(r.steps.x.back(), context_of(r, 1)))
      worst = std::max(worst, -rec.gap);
    *updates = c.multiplier_updates();
    return worst;
  };
  int updates = 0;
  const double penalty = max_penetration("", &updates);
  EXPECT_EQ(updates, 0);
  const double augmented = max_penetration(", tolerance: 1.0e-4", &updates);
  EXPECT_GT(penalty, 0.015);
  EXPECT_LT(augmented, 1e-4);
  EXPECT_GT(updates, 0);
  std::printf("augmented Lagrangian: penetration %.3e mm (penalty alone %.3e mm) after %d updates\n", augmented,
              penalty, updates);
}

// Ply pull-out (issue 12): plies 40 x 10 x 0.5, the middle one pulled along x at
// v = 1 mm/s to d = 8 mm in `steps` steps between the outer two, clamped at both ends;
// `material` (a materials entry's law) for all three, `loads` appended to the case.
// Per step after the first (which holds the start-up transient) it compares the pull
// force (reaction of the pulled edge) with F = 2 w (L0 - d) c_f v and the drag of each
// interface (sum of the friction traction over its contact points) with half of it, and
// checks that no point of the overlap has opened past the viscous layer's engage gap.
// Returns the largest relative error of F and of each interface's drag.
struct PullOutErrors {
  double force = 0.0, interface = 0.0, largest_gap = 0.0, engage_gap = 0.0;
};

PullOutErrors pull_out(const std::string& material, const std::string& elements, int steps, const std::string& loads) {
  const double w = 10.0, L0 = 40.0, cf = 0.02, v = 1.0;
  CaseRun r;
  run(R"(
materials:
  ply: {)" +
          material + R"(}
laminates:
  - name: stack
    size: [40, 10]
    elements: )" +
          elements + R"(
    layup: "[0_3]"
    ply_thickness: 0.5
    material: ply
    interface: {stiffness: 200, viscous: 0.02}
boundary_conditions:
  - clamp: {ply: stack.1, edge: x0}
  - clamp: {ply: stack.1, edge: x1}
  - clamp: {ply: stack.3, edge: x0}
  - clamp: {ply: stack.3, edge: x1}
  - displacement: {ply: stack.2, edge: x1, value: [8, 0, 0]}
)" + loads +
          "\nsolver: {steps: " + std::to_string(steps) +
          R"(, process_time: 8, tolerance: 1.0e-8}
)",
      r);
  PullOutErrors e;
  e.engage_gap = 0.01 * 0.5;  // the viscous layer's default: 0.01 ply thicknesses (mm)
  if (r.steps.x.size() != static_cast<std::size_t>(steps)) return {1e300, 1e300, 1e300, 0.0};
  const Model& m = r.problem.model;
  for (std::size_t k = 2; k <= r.steps.x.size(); ++k) {
    const double d = 8.0 * static_cast<double>(k) / steps;
    // Reaction on the pulled edge (x components of its value dofs, both layers).
    double F = 0.0;
    const PlyMesh& ply = m.ply(1);
    for (Index node = 0; node < ply.n_nodes(); ++node) {
      const Index dof = m.dof(1, node, 0, 0);
      if (std::abs(r.x0(dof) - L0) < 1e-9) F += r.steps.reactions[k - 1](dof);
    }
    const double expected = 2.0 * w * (L0 - d) * cf * v;
    e.force = std::max(e.force, std::abs(F - expected) / expected);
    std::printf("pull-out d = %.1f mm: F = %.5g N, 2 w (L0 - d) c_f v = %.5g N;", d, F, expected);
    for (int i = 0; i < m.n_interactions(); ++i) {
      const auto& c = dynamic_cast<const SurfaceContact&>(m.interaction(i));
      double drag = 0.0;
      for (const ContactPointRecord& rec : c.sample(r.steps.x[k - 1], context_of(r, k))) {
        drag += rec.weight * rec.shear.x();
        // Points of the overlap (away from the trailing end of the pulled ply).
        if (rec.partner && rec.position.x() > d + 1.0) e.largest_gap = std::max(e.largest_gap, rec.gap);
      }
      e.interface = std::max(e.interface, std::abs(std::abs(drag) - expected / 2) / (expected / 2));
      std::printf(" interface %d drag %.5g N;", i + 1, std::abs(drag));
    }
    std::printf(" largest gap %.3g mm\n", e.largest_gap);
  }
  std::printf("pull-out: largest relative error of F %.2e, of an interface's drag %.2e\n", e.force, e.interface);
  return e;
}

TEST(PlyPullOut, ForceIsTwoWidthsTimesOverlapTimesCfV) {
  // The stiff neo-Hookean stand-in (E = 1000 MPa): nothing else presses the plies together.
  const PullOutErrors e = pull_out("neo_hookean: {E: 1000, nu: 0.3}", "[6, 1]", 4, "");
  EXPECT_LT(e.force, 0.03);
  EXPECT_LT(e.interface, 0.03);
  EXPECT_LT(e.largest_gap, e.engage_gap);
}

TEST(PlyPullOut, MoltenPliesHeldByThePlatensPressureGiveTheClosedForm) {
  // The study's molten law (E_f / E_T = 25000, G_L = 0.5 MPa). The resin drag acts on the
  // inner face of each outer ply only: about its mid-plane a couple of c_f v h / 2 per unit
  // area, which a clamped ply this soft in transverse shear answers by bowing out of plane
  // (about 9 um, beyond the 5 um engage gap; docs/forming.md "Ply pull-out"). Without the
  // rig's platen pressure half of each interface opened and F came out at half the closed
  // form. A 0.001 MPa platen pressure on the outer faces (the pull-out rig's clamping
  // pressure, present from the start) keeps the plies together.
  const PullOutErrors e = pull_out("transversely_isotropic: {E_f: 25000, E_T: 1, G_L: 0.5, G_T: 0.4}", "[6, 1]", 4,
                                   R"(loads:
  - pressure: {ply: stack.3, face: top, value: 0.001, follower: false, ramp: constant}
  - pressure: {ply: stack.1, face: bottom, value: 0.001, follower: false, ramp: constant})");
  EXPECT_LT(e.force, 0.04);
  EXPECT_LT(e.interface, 0.04);
  EXPECT_LT(e.largest_gap, e.engage_gap);
}

}  // namespace
}  // namespace sf::forming
