// Plane-strain plies (`plane_strain: true`, docs/forming.md "Laminates, tools and
// contact"): u_y = 0 across the width, so a strip of one element across its width is a
// 2-D plane-strain strip.
//
//  * Exact: a compressible neo-Hookean strip (mu, lambda) stretched homogeneously along x
//    by l1 in plane strain, F = diag(l1, 1, l3), its top and bottom free: S_33 = 0 gives
//      mu (l3^2 - 1) + lambda ln(l1 l3) = 0,
//    the nominal stresses P_11 = mu (l1 - 1/l1) + lambda ln J / l1 and P_22 = lambda ln J
//    (J = l1 l3): the pulled edge carries P_11 Ly h, the held width P_22 Lx h, and
//    the thickness becomes l3 h. Without plane_strain the same strip is in uniaxial
//    stress (P_22 = 0, the width contracts).
//  * A plane-strain laminate (`plane_strain` on the laminate reaches every ply): a [0_2]
//    pair of such strips, each on its own symmetry plane, the same stretch: each ply
//    carries the exact force of its own thickness.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

struct Final final : StepObserver {
  VecX x, reactions;
  StepAction on_step(const StepInfo&, const SteppingState& s, const VecX& r) override {
    x = s.x;
    reactions = r;
    return StepAction::kContinue;
  }
};

struct Strip {
  double fx = 0.0, fy = 0.0, thickness = 0.0;
};

// Runs `text`; sums the reactions on the x and y value dofs of the ply `body` at x = Lx
// and y = Ly (reference), and its final thickness at the origin corner.
Strip run_strip(const std::string& text, int body, double lx, double ly) {
  const CaseCheck c = check_case_text(text, "plane_strain.yaml");
  EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.located(0));
  Problem problem = build_problem(c.spec);
  const Model& m = problem.model;
  const VecX X = m.reference_positions();
  SteppingState state{X, VecX::Zero(X.size()), 0.0};
  Final last;
  const SteppingReport rep = make_stepper(problem, stepper_settings(c.spec))->run(state, last);
  EXPECT_EQ(rep.status, SteppingReport::Status::kFinished) << rep.message;
  Strip out;
  const PlyMesh& ply = m.ply(body);
  const Index ns = ply.n_surface_nodes();
  for (Index node = 0; node < ply.n_nodes(); ++node) {
    const Index dx = m.dof(body, node, 0, 0), dy = m.dof(body, node, 0, 1);
    if (std::abs(X(dx) - lx) < 1e-9) out.fx += last.reactions(dx);
    if (std::abs(X(dy) - ly) < 1e-9) out.fy += last.reactions(dy);
  }
  const Index z0 = m.dof(body, 0, 0, 2), z1 = m.dof(body, ns, 0, 2);
  out.thickness = last.x(z1) - last.x(z0);
  return out;
}

std::string strip_case(bool plane_strain) {
  return std::string(R"(
materials:
  rubber: {neo_hookean: {mu: 1.0, lambda: 2.0}}
plies:
  - {name: s, size: [10, 2], thickness: 1, elements: [2, 1], material: rubber, plane_strain: )") +
         (plane_strain ? "true" : "false") + R"(}
boundary_conditions:
  - symmetry: {ply: s, plane: x0}
  - symmetry: {ply: s, plane: y0}
  - symmetry: {ply: s, plane: bottom}
  - displacement: {ply: s, edge: x1, value: [3, ~, ~]}
solver: {steps: 3, tolerance: 1.0e-12}
)";
}

// l3 from S_33 = 0 (Newton), and the nominal stresses.
void exact(double mu, double lambda, double l1, double& l3, double& p11, double& p22) {
  l3 = 1.0;
  for (int i = 0; i < 50; ++i) {
    const double f = mu * (l3 * l3 - 1.0) + lambda * std::log(l1 * l3);
    const double df = 2.0 * mu * l3 + lambda / l3;
    l3 -= f / df;
  }
  const double lnJ = std::log(l1 * l3);
  p11 = mu * (l1 - 1.0 / l1) + lambda * lnJ / l1;
  p22 = lambda * lnJ;
}

TEST(PlaneStrain, HomogeneousStretchMatchesTheExactFiniteStrainSolution) {
  const double mu = 1.0, lambda = 2.0, l1 = 1.3, lx = 10.0, ly = 2.0, h = 1.0;
  double l3 = 0, p11 = 0, p22 = 0;
  exact(mu, lambda, l1, l3, p11, p22);
  const Strip ps = run_strip(strip_case(true), 0, lx, ly);
  const double e_fx = std::abs(ps.fx - p11 * ly * h) / (p11 * ly * h);
  const double e_fy = std::abs(ps.fy - p22 * lx * h) / std::abs(p22 * lx * h);
  const double e_h = std::abs(ps.thickness - l3 * h) / (l3 * h);
  std::printf(
      "plane strain, l1 = %.2f: F_x = %.12g N (exact %.12g, %.1e), F_y = %.12g N (exact %.12g, %.1e), h = %.12g mm "
      "(exact %.12g, %.1e)\n",
      l1, ps.fx, p11 * ly * h, e_fx, ps.fy, p22 * lx * h, e_fy, ps.thickness, l3 * h, e_h);
  EXPECT_LT(e_fx, 1e-9);
  EXPECT_LT(e_fy, 1e-9);
  EXPECT_LT(e_h, 1e-9);
  // Without the option the strip is in uniaxial stress: no force across the width, and
  // a smaller pull.
  const Strip us = run_strip(strip_case(false), 0, lx, ly);
  EXPECT_NEAR(us.fy, 0.0, 1e-9);
  EXPECT_LT(us.fx, 0.95 * ps.fx);
}

TEST(PlaneStrain, LaminateOfTwoPliesSharesTheLoad) {
  const double mu = 1.0, lambda = 2.0, l1 = 1.3, lx = 10.0, ly = 2.0, h = 0.5;
  double l3 = 0, p11 = 0, p22 = 0;
  exact(mu, lambda, l1, l3, p11, p22);
  const std::string text = R"(
materials:
  rubber: {neo_hookean: {mu: 1.0, lambda: 2.0}}
laminates:
  - {name: lam, size: [10, 2], elements: [2, 1], layup: "[0_2]", ply_thickness: 0.5, material: rubber,
     plane_strain: true, interface: {stiffness: 100}}
boundary_conditions:
  - symmetry: {ply: lam.1, plane: x0}
  - symmetry: {ply: lam.1, plane: bottom}
  - displacement: {ply: lam.1, edge: x1, value: [3, ~, ~]}
  - symmetry: {ply: lam.2, plane: x0}
  - symmetry: {ply: lam.2, plane: bottom}
  - displacement: {ply: lam.2, edge: x1, value: [3, ~, ~]}
solver: {steps: 3, tolerance: 1.0e-12}
)";
  for (int body = 0; body < 2; ++body) {
    const Strip s = run_strip(text, body, lx, ly);
    const double e = std::abs(s.fx - p11 * ly * h) / (p11 * ly * h);
    std::printf("plane-strain laminate, ply %d: F_x = %.10g N (exact %.10g, %.1e)\n", body + 1, s.fx, p11 * ly * h, e);
    EXPECT_LT(e, 1e-9);
  }
}

}  // namespace
}  // namespace sf::forming
