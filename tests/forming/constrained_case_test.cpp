// Exact constraints through the case file: incompressible and inextensible plies
// solved with augmented-Lagrangian (Uzawa) updates of the element multipliers.
//
// Case B of notes/forming-verification.md §2.5: tension ACROSS inextensible fibres
// of an incompressible block, F = diag(1, lambda, 1/lambda). The law's energy is the
// standard-reinforcing one plus W_vol = -mu_T ln J + lambda_m/2 (ln J)^2, which at J = 1
// only shifts the pressure by mu_T, so
//   sigma_22 = mu_T (lambda^2 - lambda^-2),  T = mu_T (lambda^-2 - 1),
//   p = mu_T lambda^-2 - mu_T (the law's own -mu_T ln J term carries the rest).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/solve/static_solver.hpp"

namespace sf::forming {
namespace {

const char* kCaseB = R"(
materials:
  ti:
    transversely_isotropic: {mu_T: 1.0, mu_L: 3.0, kappa_f: 50.0, lambda: 5.0}
    incompressible: true
    inextensible: true
plies:
  - {name: block, size: [2, 2], thickness: 1, elements: [2, 2], angle: 0, material: ti}
boundary_conditions:
  - symmetry: {ply: block, plane: x0}
  - symmetry: {ply: block, plane: y0}
  - symmetry: {ply: block, plane: bottom}
  - displacement: {ply: block, edge: y1, value: [~, 0.6, ~]}
solver: {steps: 4, tolerance: 1.0e-10, constraint_tolerance: 1.0e-10}
)";

TEST(ConstrainedCase, TensionAcrossInextensibleFibresIsExact) {
  const CaseCheck check = check_case_text(kCaseB, "case_b.yaml");
  ASSERT_TRUE(check.ok()) << check.located(0);
  const FormingCase& spec = check.spec;
  Problem problem = build_problem(spec);
  Model& model = problem.model;
  ASSERT_TRUE(model.constrained(0));
  const RampedLoads& loads = problem.loads;
  VecX x = model.reference_positions();
  StaticOptions so;
  so.residual_tol_rel = 1e-11;
  UzawaOptions uo;
  uo.tolerance = 1e-10;
  int updates = 0;
  for (int k = 1; k <= 4; ++k) {
    const LoadFunction none = [&](double, const VecX& xs, bool t) { return loads.at(model, 0.0, xs, t); };
    UzawaReport ur;
    const StaticResult r =
        solve_static_constrained(model, x, problem.prescriptions.at(k / 4.0), none, false, so, uo, &ur);
    ASSERT_TRUE(r.report.ok()) << r.report.brief();
    updates += ur.updates;
    x = r.positions;
  }
  const double lam = 1.3, mu_t = 1.0;
  double max_g = 0.0, p_err = 0.0, t_err = 0.0;
  for (const Model::ConstraintState& c : model.constraint_state(0, x)) {
    max_g = std::max({max_g, std::abs(c.g_J), std::abs(c.g_T)});
    p_err = std::max(p_err, std::abs(c.p_eff - (mu_t / (lam * lam) - mu_t)));
    t_err = std::max(t_err, std::abs(c.T_eff - mu_t * (1.0 / (lam * lam) - 1.0)));
  }
  double f_err = 0.0;
  for (const Mat3& f : model.deformation_gradients(0, x))
    f_err = std::max(f_err, (f - Vec3(1.0, lam, 1.0 / lam).asDiagonal().toDenseMatrix()).norm());
  EXPECT_LT(max_g, 1e-10);
  EXPECT_LT(f_err, 1e-8);
  EXPECT_LT(p_err, 1e-7);
  EXPECT_LT(t_err, 1e-7);
  std::printf(
      "case B at lambda 1.3: max |g| %.1e, |F - F_exact| %.1e, |p - p_exact| %.1e, |T - T_exact| %.1e "
      "(T = %.6f), %d multiplier updates\n",
      max_g, f_err, p_err, t_err, mu_t * (1.0 / (lam * lam) - 1.0), updates);
}

TEST(ConstrainedCase, InextensibleNeedsFibres) {
  const std::string text = R"(
materials:
  rubber:
    neo_hookean: {mu: 1, lambda: 2}
    inextensible: true
plies:
  - {name: p, size: [1, 1], thickness: 1, elements: [1, 1], material: rubber}
boundary_conditions:
  - clamp: {ply: p, edge: x0}
)";
  const CaseCheck check = check_case_text(text, "bad.yaml");
  ASSERT_FALSE(check.ok());
  EXPECT_NE(check.located(0).find("inextensible needs fibres"), std::string::npos) << check.located(0);
  EXPECT_NE(check.located(0).find("bad.yaml:5:19:"), std::string::npos) << check.located(0);
}

}  // namespace
}  // namespace sf::forming
