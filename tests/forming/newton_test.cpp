// Newton iterations of the quasi-static solver on the sample cases (issue 15 item 4):
// ceilings on the counts of whole runs (deterministic, so fit for a test), the corrector's
// watchdog (a full step the line search would damp, taken once and checked), and the
// quadratic convergence of the final iterations on a sample with a consistent tangent.
// The counts before and after each change are in docs/forming.md ("Newton iterations of
// the samples").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/solve/static_solver.hpp"
#include "forming/solve/stepper.hpp"
#include "forming/solve/tangent_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

std::string sample(const char* name) { return std::string(SF_SOURCE_DIR) + "/data/forming/" + name; }

int run_iterations(const char* name) {
  const FormingCase spec = load_case(sample(name));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sf_newton_" + std::string(name));
  const fixtures::RunOutput out = fixtures::run_into(spec, dir);
  EXPECT_TRUE(out.report.ok()) << name << ": " << out.report.message;
  std::printf("[ measured ] %s: %d Newton iterations\n", name, out.report.total_iterations);
  return out.report.total_iterations;
}

// Whole run of a sample through its stepper, with or without the corrector's watchdog;
// the tool edge's x reactions of every step in `fx` (N).
struct Stepped {
  SteppingReport report;
  std::vector<double> fx;
};
class ReactionsX final : public StepObserver {
 public:
  explicit ReactionsX(std::vector<Index> dofs) : dofs_(std::move(dofs)) {}
  StepAction on_step(const StepInfo&, const SteppingState&, const VecX& reactions) override {
    double sum = 0.0;
    for (Index d : dofs_) sum += reactions(d);
    fx.push_back(sum);
    return StepAction::kContinue;
  }
  std::vector<double> fx;

 private:
  std::vector<Index> dofs_;
};
Stepped run_stepper(const char* name, bool watchdog) {
  const FormingCase spec = load_case(sample(name));
  Problem problem = build_problem(spec);
  StepperSettings settings = stepper_settings(spec);
  settings.statics.watchdog = watchdog;
  // The dofs the case moves by more than 1 mm: the pulled edge's x positions.
  std::vector<Index> dofs;
  const VecX X = problem.model.reference_positions();
  for (const PrescribedDof& p : problem.prescriptions.at(1.0))
    if (std::abs(p.value - X(p.dof)) > 1.0) dofs.push_back(p.dof);
  EXPECT_FALSE(dofs.empty()) << name << ": no dof moved by more than 1 mm";
  ReactionsX observer(dofs);
  SteppingState state{X, VecX::Zero(X.size()), 0.0};
  Stepped out;
  out.report = make_stepper(problem, settings)->run(state, observer);
  out.fx = observer.fx;
  return out;
}

// The pull-out rig: 111 iterations (one cut-back) with the residual line search alone,
// whose damping to steps of 0.01 crawled where full steps cross the viscous layer's
// 0.5 um taper and converge; 73 with the watchdog (no cut-back). The pull force is the
// same to the Newton tolerance and the sub-stepping (the viscous rates are taken over
// each converged sub-step).
// StaticOptions::extrapolate across a repeated step: a solve whose clock stands still (the
// stepper's repeats for multiplier updates) keeps the last step's span and adds its own
// correction to that step's increment. It set the span to 0, which turned the next step's
// extrapolation off. A neo-Hookean block (2 x 1 x 0.5 mm), one end held, the other
// stretched 0.2 mm over a step of 1 s; the repeat is solved from a nudged end state.
TEST(NewtonIterations, RepeatedStepKeepsTheExtrapolatingPredictorsSpan) {
  const Model model = fixtures::one_ply_model(fixtures::rectangle_ply(2.0, 1.0, 0.5, 2, 1),
                                              fixtures::neo_hookean(1.0, 2.0));
  const PlyMesh& ply = model.ply(0);
  const VecX X = model.reference_positions();
  std::vector<PrescribedDof> held, pulled;
  for (Index node = 0; node < ply.n_nodes(); ++node) {
    const Index dx = model.dof(0, node, 0, 0);
    if (X(dx) < 1e-12)
      for (int c = 0; c < 3; ++c) held.push_back({model.dof(0, node, 0, c), X(model.dof(0, node, 0, c))});
    else if (X(dx) > 2.0 - 1e-12)
      pulled.push_back({dx, X(dx) + 0.2});
  }
  ASSERT_FALSE(held.empty());
  ASSERT_FALSE(pulled.empty());
  std::vector<PrescribedDof> fixed = held;
  fixed.insert(fixed.end(), pulled.begin(), pulled.end());
  StaticOptions so;
  so.extrapolate = true;
  so.workspace = std::make_shared<TangentWorkspace>();
  so.clock = {0.0, 1.0, nullptr, 0.0};
  const StaticResult step = solve_static(model, X, fixed, VecX(), so);
  ASSERT_TRUE(step.report.ok()) << step.report.brief();
  const VecX increment = so.workspace->last_increment;
  ASSERT_EQ(so.workspace->last_span, 1.0);
  // The repeat: the time standing at the step's end, from a state off the equilibrium.
  VecX nudged = step.positions;
  for (Index i = 0; i < nudged.size(); ++i) nudged(i) += 1e-4 * std::sin(0.9 * double(i));
  for (const PrescribedDof& p : fixed) nudged(p.dof) = p.value;
  StaticOptions repeat = so;
  repeat.clock = {1.0, 1.0, &X, 0.0};
  const StaticResult again = solve_static(model, nudged, fixed, VecX(), repeat);
  ASSERT_TRUE(again.report.ok()) << again.report.brief();
  EXPECT_EQ(so.workspace->last_span, 1.0);  // 0 before: the next step would not extrapolate
  ASSERT_EQ(so.workspace->last_increment.size(), X.size());
  const VecX expected = increment + (again.positions - nudged);
  EXPECT_LT((so.workspace->last_increment - expected).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((so.workspace->last_increment - (again.positions - X)).lpNorm<Eigen::Infinity>(), 2e-4);
}

TEST(NewtonIterations, WatchdogTakesThePulloutThroughTheViscousTaper) {
  const Stepped with = run_stepper("ply_pullout.yaml", true);
  const Stepped without = run_stepper("ply_pullout.yaml", false);
  std::printf("[ measured ] ply_pullout: %d Newton iterations with the watchdog, %d without\n",
              with.report.total_iterations, without.report.total_iterations);
  ASSERT_EQ(with.report.status, SteppingReport::Status::kFinished) << with.report.message;
  ASSERT_EQ(without.report.status, SteppingReport::Status::kFinished) << without.report.message;
  EXPECT_LE(with.report.total_iterations, 80);
  EXPECT_GT(without.report.total_iterations, 100);
  ASSERT_EQ(with.fx.size(), without.fx.size());
  ASSERT_FALSE(with.fx.empty());
  for (std::size_t k = 0; k < with.fx.size(); ++k) {
    std::printf("  step %zu: pull force %.5f N (without: %.5f N)\n", k + 1, std::abs(with.fx[k]),
                std::abs(without.fx[k]));
    EXPECT_NEAR(with.fx[k], without.fx[k], 1e-3 * std::abs(without.fx[k])) << "step " << k + 1;
  }
}

// Samples whose counts the watchdog does not lower: ceilings a little above today's, so
// a change that makes them converge worse shows here (the pull-out: above).
TEST(NewtonIterations, CantileverAndOffAxisSamplesWithinCeilings) {
  EXPECT_LE(run_iterations("cantilever.yaml"), 100);  // 87 before the watchdog, 93 with it
  EXPECT_LE(run_iterations("uniaxial_45.yaml"), 70);  // 59 before, 64 with it
  EXPECT_LE(run_iterations("free_bending.yaml"), 15);
  EXPECT_LE(run_iterations("uniaxial_0.yaml"), 8);
}

// The shear-and-stretch ply of the benchmark (bench/cases/shear_stretch_ply.yaml, issue
// 15: fibres at 30 degrees, the far edge moved 4 mm across and 2 mm along in two steps,
// stretching the fibres that span the two edges by 1.93 %) at 4 x 4 elements instead of
// 40 x 40, the coarsest mesh on which it finishes: 71 Newton iterations (13 and 58, three
// cut-backs in step 2) on 2026-12-03. A ceiling, so that a change that makes it worse
// shows; the finer meshes (6 x 6: 154, five cut-backs; 8 x 8 and up: fails in step 1)
// are in docs/forming.md ("Newton iterations of the samples").
TEST(NewtonIterations, ShearAndStretchPlyAtFourByFourWithinCeiling) {
  FormingCase spec = load_case(std::string(SF_SOURCE_DIR) + "/bench/cases/shear_stretch_ply.yaml");
  ASSERT_EQ(spec.plies.size(), 1u);
  spec.plies[0].n1 = spec.plies[0].n2 = 4;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sf_newton_shear_stretch_4x4";
  const fixtures::RunOutput out = fixtures::run_into(spec, dir);
  ASSERT_TRUE(out.report.ok()) << out.report.message;
  std::printf("[ measured ] shear-and-stretch ply, 4 x 4 elements: %d Newton iterations\n",
              out.report.total_iterations);
  EXPECT_LE(out.report.total_iterations, 80);
}

// One load step of a sample solved directly (so the per-iteration record is kept).
StaticResult solve_first_step(const char* name, double lambda, const StaticOptions& options) {
  const FormingCase spec = load_case(sample(name));
  Problem problem = build_problem(spec);
  const LoadFunction load = [&](double s, const VecX& x, bool want_tangent) {
    return problem.loads.at(problem.model, s * lambda, x, want_tangent);
  };
  return solve_static(problem.model, problem.model.reference_positions(), problem.prescriptions.at(lambda), load,
                      problem.loads.follower, options);
}

// Quadratic convergence at the end of a step of the 45-degree ply (consistent tangent):
// with e_k = |r_k| / force scale, log e_{k+1} / log e_k approaches 2 once e_k is small.
TEST(NewtonIterations, OffAxisPlyConvergesQuadraticallyAtTheEnd) {
  StaticOptions o;
  o.residual_tol_rel = 1e-10;  // round-off of |r| / force scale: about 4e-11 here
  o.max_iterations = 30;
  const StaticResult r = solve_first_step("uniaxial_45.yaml", 0.05, o);
  ASSERT_TRUE(r.report.ok()) << r.report.brief();
  int checked = 0;
  for (const StepRecord& s : r.report.steps) {
    if (!s.converged) continue;
    std::printf("  step to %.3f: e =", s.target);
    for (double n : s.residual_norms) std::printf(" %.2e", n / r.report.force_scale);
    std::printf("\n");
    for (std::size_t k = 0; k + 1 < s.residual_norms.size(); ++k) {
      const double e0 = s.residual_norms[k] / r.report.force_scale;
      const double e1 = s.residual_norms[k + 1] / r.report.force_scale;
      if (e0 > 1e-2) continue;  // outside the asymptotic range
      const double order = std::log(e1) / std::log(e0);
      std::printf("  log e_%zu / log e_%zu = %.2f\n", k + 1, k, order);
      // Measured 1.62 then 2.20 (e 1.6e-3 -> 2.8e-5 -> 9.8e-11); a linear rate gives ~1.
      EXPECT_GT(order, 1.5) << "step to " << s.target << ", iteration " << k + 1;
      ++checked;
    }
  }
  EXPECT_GE(checked, 2) << "too few iterations in the asymptotic range";
}

}  // namespace
}  // namespace sf::forming
