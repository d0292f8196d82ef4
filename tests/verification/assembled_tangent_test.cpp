// The full assembled tangent of a forming model in contact against central finite
// differences of its assembled residual (issue 12: "finite-difference tangent test of
// two-pass contact"; issue 13: Newton under contact). Unlike contact_tangent_test.cpp,
// which checks the contact kernel on idealised states, this builds the quick matched-die
// bend of data/forming/processes/ (three molten fibre plies, plane strain; a die with a
// slot and an edge radius, a holder, a cylindrical punch; two-pass ply-ply contact with
// viscous + Coulomb friction), solves its first load step, and evaluates the model at a
// state of the second step as Newton meets it: the punch moved on, the plies part-way
// after it and perturbed, so contact points press on the punch's round nose and on the
// die's edge radius, ply-ply foot points move, and the plies slide (quasi-static rates
// over the step). It compares
//   * d force / dx of the whole model (elements + every interaction) with the tangent
//     Model::assemble returns, and
//   * the same for each interaction alone (punch, die, holder, each ply-ply pass),
// relative to the largest entry of each. A term left out of the contact tangent (the
// tool's curvature, the moving foot point, friction's rate or pressure terms, the second
// pass's master columns) shows as an error of 1e-3 or more (measured: without the viscous
// taper's term every ply-ply pass 3.6e-3 .. 8.8e-3; without the tool's curvature term the
// punch 4.0e-2, the die 4.9e-4); the complete tangent measures 1e-10 .. 4e-9.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/contact/surface_contact.hpp"
#include "forming/solve/stepper.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

constexpr double kFdStep = 1e-6;  // mm (positions O(10))
// FD tangent against the analytic one, relative to the largest entry (measured below
// 1e-6 for the whole model and for each interaction; a missing term gives >= 1e-3).
constexpr double kFdRel = 1e-5;

// The quick bend with three plies, two-pass interfaces and combined friction.
const char* kBend = R"(units: "mm, N, MPa, s"
materials:
  gfpp_melt: {transversely_isotropic: {E_f: 25000, E_T: 1, G_L: 0.5, G_T: 0.4}}
laminates:
  - name: lam
    size: [24, 5]
    elements: [8, 1]
    layup: "[0_3]"
    ply_thickness: 0.5
    material: gfpp_melt
    plane_strain: true
    interface: {stiffness: 50, viscous: 0.02, coulomb: 0.2, stick_velocity: 0.05, two_pass: true, band: 0.005}
tools:
  - name: die
    die: {centre: [0, 0, 0], normal: [0, 0, 1], slot_half_width: 8, along: [0, 1, 0], edge_radius: 3}
    motion: {fixed: true}
  - name: holder
    die: {centre: [0, 0, 1.5], normal: [0, 0, -1], slot_half_width: 8, along: [0, 1, 0], edge_radius: 3}
    motion: {fixed: true}
  - name: punch
    cylinder: {point: [0, 0, 7.5], axis: [0, 1, 0], radius: 6}
    motion: {displacement: [0, 0, -4], ramp: linear}
contact:
  - {ply: lam.1, face: bottom, tool: die, stiffness: 50, band: 0.005}
  - {ply: lam.3, face: top, tool: punch, stiffness: 50, band: 0.005}
  - {ply: lam.3, face: top, tool: holder, stiffness: 50, band: 0.005}
boundary_conditions:
  - symmetry: {ply: lam.1, plane: x0}
  - symmetry: {ply: lam.2, plane: x0}
  - symmetry: {ply: lam.3, plane: x0}
solver: {steps: 8, process_time: 0.5, max_iterations: 60, tolerance: 1.0e-7}
)";

// Keeps the converged states and stops after `stop_after` steps.
class Keep final : public StepObserver {
 public:
  explicit Keep(int stop_after) : stop_after_(stop_after) {}
  StepAction on_step(const StepInfo& step, const SteppingState& state, const VecX&) override {
    states.push_back(state.x);
    iterations.push_back(step.iterations);
    return step.index >= stop_after_ ? StepAction::kStop : StepAction::kContinue;
  }
  std::vector<VecX> states;
  std::vector<int> iterations;

 private:
  int stop_after_;
};

struct Sample {
  VecX force;
  MatX stiffness;  // empty unless asked for
};

Sample model_at(const Model& m, const VecX& x, const InteractionContext& ctx, bool tangent) {
  const Assembly a = m.assemble(x, ctx, tangent);
  EXPECT_TRUE(a.ok) << a.message;
  Sample s{a.force, {}};
  if (tangent) s.stiffness = MatX(a.tangent);
  return s;
}

Sample interaction_at(const Interaction& c, Index n, const VecX& x, const InteractionContext& ctx, bool tangent) {
  InteractionSums sums;
  sums.force = VecX::Zero(n);
  linalg::TripletAssembler k(n, n);
  if (tangent) sums.stiffness = &k;
  c.add_to(x, ctx, sums);
  EXPECT_TRUE(sums.ok) << sums.message;
  Sample s{sums.force, {}};
  if (tangent) s.stiffness = MatX(k.compress());
  return s;
}

// max |K_fd - K| / max |K| over the columns `cols`.
template <class Eval>
double fd_error(Eval&& eval, const VecX& x, const std::vector<Index>& cols) {
  const Sample s = eval(x, true);
  double err = 0.0;
  for (const Index j : cols) {
    VecX xp = x, xm = x;
    xp(j) += kFdStep;
    xm(j) -= kFdStep;
    const VecX col = (eval(xp, false).force - eval(xm, false).force) / (2 * kFdStep);
    Index row = 0;
    const double ej = (col - s.stiffness.col(j)).cwiseAbs().maxCoeff(&row);
    if (std::getenv("SF_FD_DETAIL") && ej > 1e-4 * max_abs(s.stiffness))
      std::printf("  col %ld row %ld: fd %.6g analytic %.6g\n", long(j), long(row), col(row), s.stiffness(row, j));
    err = std::max(err, ej);
  }
  const double scale = max_abs(s.stiffness);
  return scale > 0.0 ? err / scale : err;
}

struct BendState {
  Problem problem;
  VecX previous, x;
  InteractionContext context;
};

// The bend after one converged step, at a state of step 2 as Newton meets it.
BendState bend_state() {
  const CaseCheck c = check_case_text(kBend, "assembled_tangent_bend.yaml");
  EXPECT_TRUE(c.ok()) << c.located(0);
  BendState b{build_problem(c.spec), {}, {}, {}};
  const StepperSettings settings = stepper_settings(c.spec);
  SteppingState state;
  state.x = b.problem.model.reference_positions();
  Keep keep(1);
  const SteppingReport rep = make_stepper(b.problem, settings)->run(state, keep);
  EXPECT_EQ(keep.states.size(), 1u) << rep.message;
  const double T = settings.process_time;
  const double t1 = T / settings.steps, t2 = 2 * t1;
  b.previous = keep.states.back();
  // Part-way after the punch: the step's own displacement again, half of it, and noise
  // of 2e-3 mm on every dof (curved, non-equilibrium, sliding).
  const VecX step1 = b.previous - b.problem.model.reference_positions();
  b.x = b.previous + 0.5 * step1;
  std::mt19937 rng(test::kSeed + 41);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < b.x.size(); ++i) b.x(i) += 2e-3 * u(rng);
  b.context = InteractionContext{t2, nullptr, &b.previous, t1};
  return b;
}

// Dofs the tangent touches (non-zero column).
std::vector<Index> touched(const MatX& K) {
  std::vector<Index> cols;
  for (Index j = 0; j < K.cols(); ++j)
    if (K.col(j).cwiseAbs().maxCoeff() > 0.0) cols.push_back(j);
  return cols;
}

TEST(AssembledTangent, MatchedDieBendInContactAgreesWithFiniteDifferences) {
  BendState b = bend_state();
  const Model& m = b.problem.model;
  const Index n = m.n_dofs();
  // The state is what the test is about: points press on the punch's nose and on the
  // die's edge radius, and every ply-ply pass has closed points.
  int on_radius = 0, on_punch = 0;
  for (int i = 0; i < m.n_interactions(); ++i) {
    const auto* sc = dynamic_cast<const SurfaceContact*>(&m.interaction(i));
    ASSERT_NE(sc, nullptr);
    int closed = 0;
    for (const ContactPointRecord& r : sc->sample(b.x, b.context)) {
      if (!(r.partner && r.pressure > 0.0)) continue;
      ++closed;
      const bool tilted = std::abs(r.normal.x()) > 0.05 && std::abs(r.normal.z()) > 0.05;
      if (sc->name().find("die") != std::string::npos && tilted) ++on_radius;
      if (sc->name().find("punch") != std::string::npos && tilted) ++on_punch;
    }
    std::printf("[ measured ] %s: %d points carry pressure\n", sc->name().c_str(), closed);
    if (sc->name().find("holder") == std::string::npos) {
      EXPECT_GT(closed, 0) << sc->name();
    }
  }
  EXPECT_GT(on_radius, 0);
  EXPECT_GT(on_punch, 0);

  // Each interaction alone.
  for (int i = 0; i < m.n_interactions(); ++i) {
    const Interaction& c = m.interaction(i);
    const auto eval = [&](const VecX& x, bool tangent) { return interaction_at(c, n, x, b.context, tangent); };
    const Sample s = eval(b.x, true);
    if (max_abs(s.stiffness) == 0.0) continue;
    const double e = fd_error(eval, b.x, touched(s.stiffness));
    std::printf("[ measured ] %s: FD tangent error %.2e (largest entry %.3g N/mm)\n", c.name().c_str(), e,
                max_abs(s.stiffness));
    EXPECT_LT(e, kFdRel) << c.name();
  }
  // The whole model, as the solver assembles it.
  const auto eval = [&](const VecX& x, bool tangent) { return model_at(m, x, b.context, tangent); };
  const Sample s = eval(b.x, true);
  // Every fifth column (the interactions' own columns are all checked above; 12 dofs a
  // node, so every parameter and coordinate is sampled): the elements' kernels have their
  // own FD tests, and each column costs two assemblies.
  std::vector<Index> cols;
  for (const Index j : touched(s.stiffness))
    if (j % 5 == 0) cols.push_back(j);
  const double e = fd_error(eval, b.x, cols);
  std::printf("[ measured ] whole model: FD tangent error %.2e (largest entry %.3g N/mm)\n", e, max_abs(s.stiffness));
  EXPECT_LT(e, kFdRel);
}

}  // namespace
}  // namespace sf::forming
