// Finite-deformation patch tests of the ply brick (notes/forming-verification.md
// section 2.1) solved with the static Newton solver (forming/solve/static_solver.hpp).
//
// Ply: 3 x 2 bricks on a graded rectangle (3 x 2 mm, thickness 0.25 mm) with every
// node's in-plane derivative parameters skewed and cross derivatives non-zero, the
// interior nodes moved, and the top face distorted differently from the bottom one
// (both faces stay flat, z = 0 and z = h, so their reference normal is e3).
// Boundary: every parameter (value, d/ds1, d/ds2, d2/ds1ds2; x, y, z) of the nodes on
// the ply's lateral boundary (surface boundary nodes, both layers) is prescribed as
// x = F0 X + t, i.e. values F0 X + t and derivative parameters F0 times the reference
// ones. The faces z = 0 and z = h are free (traction free), so the exact solution is
// homogeneous only when F0 gives a plane stress state, S e3 = 0: F0 = R [u1 u2 c] with
// the in-plane columns u1, u2 given (stretch and shear, with a small out-of-plane
// part), c solved from S(C) e3 = 0 for each material, and R a 60 degree rotation about
// an oblique axis. The interior parameters (both layers, 48 dofs) must then return
// F0 X + t to round-off, F = F0 at every Gauss point, and Newton must converge
// quadratically. Compressible neo-Hookean and compressible TI (fibres at 30 degrees
// to the mesh lines).
//
// Also: a load path that must invert elements (mirror through the ply plane) ends in
// a step-failed report with the last converged state (no loop, no throw), and bad
// options are rejected by name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "common/core/error.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// ---- Named tolerances -----------------------------------------------------------
// Interior parameters against F0 X + t and Gauss-point F against F0 (brief: 1e-10;
// positions O(3) mm, Newton stopped at |r| <= 1e-13 of the force scale).
constexpr double kPatchExact = 1e-10;
// Newton stopping tolerance in the patch tests, relative to the force scale: close to
// round-off so the final iterations show the convergence rate.
constexpr double kNewtonTolRel = 1e-13;
// Quadratic convergence: e_{k+1} <= kQuadraticBound e_k^2 for the normalised residuals
// e = |r| / force_scale once e_k <= kAsymptotic (final iterations), for e_{k+1} above
// the round-off floor. Measured ratios 0.015..42 (neo-Hookean), 1.4..1.7 (TI); a
// linearly converging Newton (rate c) gives c / e_k, i.e. >= 1e4 c at e_k = 1e-4.
constexpr double kQuadraticBound = 100.0;
constexpr double kAsymptotic = 1e-2;
constexpr double kRoundoffFloor = 1e-14;
// Plane-stress F0 solve: |S e3| relative to mu.
constexpr double kPlaneStress = 1e-14;

struct Patch {
  std::unique_ptr<Model> model;
  std::vector<Index> boundary_nodes;  // ply nodes (both layers)
  std::vector<Index> interior_nodes;
};

// The distorted, graded 3 x 2 ply described in the file header.
PlyMesh distorted_ply(double layup_angle) {
  mesh::SurfaceMesh s = mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 2.0, 3, 2,
                                                  {0.0, 0.8, 1.9, 3.0}, {0.0, 1.15, 2.0});
  const double h = 0.25;
  MatX bottom = s.geometry();
  MatX top = bottom;
  const Index ns = s.n_nodes();
  for (Index node = 0; node < ns; ++node) {
    const int i = static_cast<int>(node % 4), j = static_cast<int>(node / 4);  // 4 x 3 nodes
    const bool interior = i > 0 && i < 3 && j == 1;
    auto row = [](Index n, int d) { return mesh::SurfaceMesh::dof(n, d); };
    const double w = 0.07 * std::sin(1.3 * node + 0.4);
    // Skewed tangents and a cross derivative at every node (boundary ones too: their
    // prescribed values follow from F0), stronger on the top face.
    bottom.row(row(node, mesh::kD1)) += Eigen::RowVector3d(0.05 + w, 0.12, 0.0);
    bottom.row(row(node, mesh::kD2)) += Eigen::RowVector3d(-0.1, -0.04 + w, 0.0);
    bottom.row(row(node, mesh::kD12)) += Eigen::RowVector3d(0.06, -0.05 * (1 + i), 0.0);
    top.row(row(node, mesh::kD1)) += Eigen::RowVector3d(-0.04, 0.09 - w, 0.0);
    top.row(row(node, mesh::kD2)) += Eigen::RowVector3d(0.08 + w, 0.05, 0.0);
    top.row(row(node, mesh::kD12)) += Eigen::RowVector3d(-0.03 * j, 0.07, 0.0);
    top.row(row(node, mesh::kValue)) += Eigen::RowVector3d(0.0, 0.0, h);
    if (interior) {
      bottom.row(row(node, mesh::kValue)) += Eigen::RowVector3d(0.13 * (i == 1 ? 1 : -1), -0.09, 0.0);
      top.row(row(node, mesh::kValue)) += Eigen::RowVector3d(-0.06, 0.11 * (i == 1 ? 1 : -1), 0.0);
    }
  }
  return PlyMesh(std::move(s), bottom, top, h, layup_angle);
}

// F0 = R [u1 u2 c] with S(C) e3 = 0 (Newton on c with a finite-difference Jacobian).
Mat3 plane_stress_f0(const Material& material) {
  Mat3 U;
  U << 1.25, 0.2, 0.0,  //
      0.1, 0.85, 0.0,   //
      0.04, -0.03, 1.0;
  auto g = [&](const Mat3& u) -> Vec3 { return material.evaluate(u.transpose() * u, false).stress.col(2); };
  for (int it = 0; it < 50 && g(U).norm() > kPlaneStress; ++it) {
    Mat3 J;
    const double h = 1e-7;
    for (int k = 0; k < 3; ++k) {
      Mat3 up = U, um = U;
      up(k, 2) += h;
      um(k, 2) -= h;
      J.col(k) = (g(up) - g(um)) / (2 * h);
    }
    U.col(2) -= J.lu().solve(g(U));
  }
  EXPECT_LT(g(U).norm(), kPlaneStress);
  const Mat3 R = Eigen::AngleAxisd(60.0 * kPi / 180.0, Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Mat3 F0 = R * U;
  EXPECT_GT(F0.determinant(), 0.0);
  return F0;
}

// Every parameter of the ply's lateral boundary nodes (both layers) at its value in target.
std::vector<PrescribedDof> prescribe_boundary(const Model& model, const VecX& target) {
  return fixtures::held_at(fixtures::node_dofs(model, 0, model.ply(0).boundary_surface_nodes()), target);
}

void run_patch(const std::shared_ptr<const Material>& material, const PlyMesh& ply_in, const char* label) {
  Model model;
  model.add_ply(ply_in, material);
  const PlyMesh& ply = model.ply(0);
  const Mat3 F0 = plane_stress_f0(*material);
  const Vec3 t(0.3, -0.2, 0.5);
  const VecX exact = fixtures::affine(ply, F0, t);
  const std::vector<PrescribedDof> bcs = prescribe_boundary(model, exact);
  ASSERT_EQ(bcs.size(), static_cast<std::size_t>(10 * 2 * 4 * 3));  // 10 boundary nodes of 12

  StaticOptions options;
  options.residual_tol_rel = kNewtonTolRel;
  options.initial_increment = 0.5;
  options.max_steps = 40;  // a broken tangent then fails in seconds, not minutes
  const StaticResult res = solve_static(model, model.reference_positions(), bcs, VecX(), options);
  std::printf("%s: %s\n", label, res.report.brief().c_str());
  ASSERT_TRUE(res.report.ok()) << res.report.brief();
  for (const StepRecord& s : res.report.steps) {
    std::printf("  step to lambda %.3f (%s), |r|/scale:", s.target, s.converged ? "converged" : "failed");
    for (double r : s.residual_norms) std::printf(" %.2e", r / res.report.force_scale);
    std::printf("; line-search factors:");
    for (double a : s.step_lengths) std::printf(" %.3g", a);
    std::printf("\n");
  }

  // Interior parameters reproduce F0 X + t; every dof does (boundary ones by construction).
  const double pos_err = (res.positions - exact).lpNorm<Eigen::Infinity>();
  EXPECT_LT(pos_err, kPatchExact);
  // F = F0 at every Gauss point.
  double f_err = 0.0;
  for (const Mat3& F : model.deformation_gradients(0, res.positions))
    f_err = std::max(f_err, (F - F0).cwiseAbs().maxCoeff());
  EXPECT_LT(f_err, kPatchExact);
  std::printf("  max |x - (F0 X + t)| = %.2e mm, max |F - F0| = %.2e over %zu Gauss points\n", pos_err, f_err,
              model.deformation_gradients(0, res.positions).size());

  // Quadratic convergence in the final (asymptotic) iterations of every step:
  // e_{k+1} / e_k^2 bounded once e_k <= kAsymptotic, for e_{k+1} above round-off.
  int checked = 0;
  std::vector<double> e;
  for (const StepRecord& s : res.report.steps) {
    e.clear();
    for (double r : s.residual_norms) e.push_back(r / res.report.force_scale);
    for (std::size_t k = 0; k + 1 < e.size(); ++k) {
      if (e[k] > kAsymptotic || e[k + 1] <= kRoundoffFloor) continue;
      const double ratio = e[k + 1] / (e[k] * e[k]);
      std::printf("  lambda %.2f: e_%zu / e_%zu^2 = %.3g\n", s.target, k + 1, k, ratio);
      EXPECT_LT(ratio, kQuadraticBound) << "step to lambda " << s.target << ", iteration " << k + 1;
      ++checked;
    }
  }
  EXPECT_GE(checked, 2) << "too few iterations above round-off to show the rate";
  EXPECT_LE(e.back(), kNewtonTolRel);
}

TEST(FormingPatch, NeoHookeanDistortedGradedMeshReproducesF0) {
  run_patch(std::make_shared<NeoHookean>(NeoHookeanParams{1.0, 3.0}), distorted_ply(0.0), "neo-Hookean patch");
}

TEST(FormingPatch, TransverselyIsotropicDistortedGradedMeshReproducesF0) {
  PlyMesh ply = distorted_ply(30.0);
  TransverselyIsotropicParams p;
  p.mu_T = 1.0;
  p.mu_L = 2.5;
  p.kappa_f = 40.0;
  p.incompressible = false;
  p.lambda = 3.0;
  run_patch(std::make_shared<TransverselyIsotropic>(p, ply.fibre_direction()), ply, "TI patch (fibres 30 deg)");
}

TEST(FormingPatch, UnreachableStateEndsWithReportAndLastConvergedState) {
  Model model;
  model.add_ply(distorted_ply(0.0), std::make_shared<NeoHookean>(NeoHookeanParams{1.0, 3.0}));
  // Mirror through the ply plane: the boundary passes through zero thickness at lambda 1/2.
  Mat3 M = Mat3::Identity();
  M(2, 2) = -1.0;
  const VecX target = fixtures::affine(model.ply(0), M, Vec3::Zero());
  StaticOptions options;
  options.initial_increment = 0.25;
  options.min_increment = 1e-3;
  const StaticResult res =
      solve_static(model, model.reference_positions(), prescribe_boundary(model, target), VecX(), options);
  std::printf("mirror: %s\n", res.report.brief().c_str());
  EXPECT_EQ(res.report.status, StaticReport::Status::kStepFailed);
  EXPECT_THAT(res.report.message, ::testing::HasSubstr("failed"));
  EXPECT_GT(res.report.load_factor, 0.25);
  // At lambda 1/2 the boundary nodes lie in one plane, but the Gauss points are inside
  // and may keep det F > 0 (the line search that follows the potential reaches that
  // state; the check below asserts it is admissible); no state beyond it is.
  EXPECT_LE(res.report.load_factor, 0.5);
  EXPECT_GT(res.report.n_cutbacks, 0);
  EXPECT_LE(static_cast<int>(res.report.steps.size()), options.max_steps);
  EXPECT_TRUE(model.assemble(res.positions, false).ok);  // usable partial result

  StaticOptions few;
  few.initial_increment = 0.01;
  few.max_increment = 0.01;
  few.max_steps = 3;
  const StaticResult capped =
      solve_static(model, model.reference_positions(), prescribe_boundary(model, target), VecX(), few);
  EXPECT_EQ(capped.report.status, StaticReport::Status::kStepFailed);
  EXPECT_THAT(capped.report.message, ::testing::HasSubstr("max_steps"));
  EXPECT_NEAR(capped.report.load_factor, 0.03, 1e-12);
}

// After a cut-back (here: a small first increment) the increment grows again after
// regrow_after converged sub-steps in a row, even when none converges within
// easy_iterations (under contact none does: the matched-die bends).
TEST(FormingPatch, IncrementGrowsAgainAfterStepsInARow) {
  Model model;
  model.add_ply(distorted_ply(0.0), std::make_shared<NeoHookean>(NeoHookeanParams{1.0, 3.0}));
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.3;
  F(0, 1) = 0.2;
  const VecX target = fixtures::affine(model.ply(0), F, Vec3::Zero());
  StaticOptions options;
  options.initial_increment = 1.0 / 16.0;
  options.easy_iterations = 1;  // no step is easy (each takes a few Newton iterations)
  auto run = [&](int regrow_after) {
    StaticOptions o = options;
    o.regrow_after = regrow_after;
    return solve_static(model, model.reference_positions(), prescribe_boundary(model, target), VecX(), o);
  };
  const StaticResult fixed = run(0), regrown = run(2);
  ASSERT_TRUE(fixed.report.ok()) << fixed.report.brief();
  ASSERT_TRUE(regrown.report.ok()) << regrown.report.brief();
  std::printf("increment 1/16: %d steps without regrowth, %d with it (every 2nd step x1.5)\n",
              fixed.report.n_converged_steps, regrown.report.n_converged_steps);
  EXPECT_EQ(fixed.report.n_converged_steps, 16);
  // 1/16 twice, 3/32 twice, 9/64 twice, 27/128 twice: 1 is reached in 8 steps (the last shortened).
  EXPECT_EQ(regrown.report.n_converged_steps, 8);
  EXPECT_NEAR(regrown.report.steps[2].increment, 1.5 / 16.0, 1e-12);
  EXPECT_NEAR(regrown.positions.dot(regrown.positions), fixed.positions.dot(fixed.positions),
              1e-8 * fixed.positions.squaredNorm());
}

TEST(FormingPatch, BadOptionsAndInputsAreNamed) {
  StaticOptions o;
  o.max_iterations = 0;
  try {
    o.validate();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("max_iterations"));
  }
  Model model;
  model.add_ply(distorted_ply(0.0), std::make_shared<NeoHookean>(NeoHookeanParams{1.0, 3.0}));
  const StaticResult r = solve_static(model, model.reference_positions(), {{model.n_dofs(), 0.0}}, VecX());
  EXPECT_EQ(r.report.status, StaticReport::Status::kInvalidStart);
  EXPECT_THAT(r.report.message, ::testing::HasSubstr("prescribed dof"));
  EXPECT_THROW(PlyMesh(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1, 1, 1, 1), -1.0, 0.0),
               InputError);
}

}  // namespace
}  // namespace sf::forming
