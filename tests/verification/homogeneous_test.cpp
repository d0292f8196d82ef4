// Homogeneous-deformation verification of the ply brick with the transversely isotropic
// law (notes/forming-verification.md section 2.5):
//
//  * Objectivity. A block (3 x 2 bricks, fibres at 30 degrees to the mesh lines) is
//    deformed (a) homogeneously, every parameter prescribed as F0 X, and (b) with only
//    the lateral boundary prescribed as F0 X and the faces z = 0, h free (a non-trivial
//    equilibrium solved by Newton). Both are repeated with x -> R x + t for a large
//    rigid rotation R (120 degrees about an oblique axis): the internal energy must be
//    identical, the reactions (per parameter, a 3-vector) must be R times the
//    unrotated ones, and in (b) the solution must be R x + t, all to round-off.
//    In (a) the energy must also equal W(F0^T F0) times the volume.
//
//  * Simple shear along the fibres. F = I + gamma e1 (x) e2 with fibres along e1: for
//    the compressible TI law (J = 1, I4 = 1, I5 = 1 + gamma^2) the exact stresses are
//    S = [[-mu_T g^2, mu_L g, 0], [mu_L g, 0, 0], [0, 0, 0]] and
//    P = F S = [[(mu_L - mu_T) g^2, mu_L g, 0], [mu_L g, 0, 0], [0, 0, 0]],
//    sigma_12 = P_12 = mu_L g = G_L g exactly at any g; P e3 = 0, so the faces z = 0, h
//    are traction free and the homogeneous state is the equilibrium with the lateral
//    boundary prescribed. Measured: the interior (free) parameters, the shear stress from
//    the reactions on the face y = L2 (sum of the x reactions of its value parameters /
//    (L1 h); the Hermite value functions sum to one on a face, and the x = 0 / x = L1
//    faces' P_11 contributions to the two corner nodes cancel), and the mean first
//    Piola-Kirchhoff stress from the virial sum_p r_p X_p^T / V over all parameters
//    (exact because the Hermite interpolation reproduces X including its derivative
//    parameters).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "common/mesh/surface_mesh.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

// Round-off bounds (relative to the scale of the compared quantity). The sums run over
// a few hundred O(1) terms, so 1e-12 leaves a margin of ~100 over the measured 1e-14.
constexpr double kRoundoff = 1e-12;
// Newton stopping tolerance relative to the force scale.
constexpr double kNewtonTol = 1e-13;

TransverselyIsotropicParams ti_params() { return fixtures::ti_compressible(1.0, 2.5, 40.0, 3.0); }

using fixtures::affine;

// Rigid motion x -> R x + t of a flattened position field.
VecX rigid(const VecX& x, const Mat3& R, const Vec3& t) {
  MatX m = PlyMesh::unflatten(x);
  for (Index p = 0; p < m.rows(); ++p) {
    m.row(p) = (R * m.row(p).transpose()).transpose();
    if (p % 4 == mesh::kValue) m.row(p) += t.transpose();
  }
  return PlyMesh::flatten(m);
}

// Rotation of a flattened force field (per parameter).
VecX rotate(const VecX& f, const Mat3& R) { return rigid(f, R, Vec3::Zero()); }

// Every parameter of the lateral boundary nodes (or of every node), at its value in target.
std::vector<PrescribedDof> prescribe(const Model& model, const VecX& target, bool lateral_only) {
  const PlyMesh& ply = model.ply(0);
  const std::vector<Index> nodes = lateral_only ? ply.boundary_surface_nodes() : fixtures::all_surface_nodes(ply);
  return fixtures::held_at(fixtures::node_dofs(model, 0, nodes), target);
}

StaticResult solve(const Model& model, const std::vector<PrescribedDof>& bcs, const VecX& start) {
  StaticOptions o;
  o.residual_tol_rel = kNewtonTol;
  o.initial_increment = 0.5;
  o.max_steps = 40;
  return solve_static(model, start, bcs, VecX(), o);
}

using fixtures::max_abs;

TEST(VerificationObjectivity, TransverselyIsotropicEnergyAndReactionsAreFrameIndifferent) {
  PlyMesh ply0(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 2.0, 3, 2,
                                         {0.0, 0.7, 1.9, 3.0}, {0.0, 1.2, 2.0}),
               0.5, 30.0);
  auto material = std::make_shared<TransverselyIsotropic>(ti_params(), ply0.fibre_direction());
  Model model;
  model.add_ply(ply0, material);
  const PlyMesh& ply = model.ply(0);
  Mat3 F0;
  F0 << 1.2, 0.15, 0.05,  //
      -0.1, 0.9, 0.02,    //
      0.03, -0.04, 1.05;
  const Mat3 R = Eigen::AngleAxisd(120.0 * kPi / 180.0, Vec3(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const Vec3 t(5.0, -3.0, 2.0);

  // (a) Homogeneous: every parameter prescribed, no solve needed.
  const VecX xa = affine(ply, F0, Vec3::Zero());
  const VecX xa_rot = rigid(xa, R, t);
  const Assembly a = model.assemble(xa, false);
  const Assembly a_rot = model.assemble(xa_rot, false);
  ASSERT_TRUE(a.ok && a_rot.ok);
  const double volume = 3.0 * 2.0 * 0.5;
  const double w_exact = material->evaluate(F0.transpose() * F0, false).energy * volume;
  const double e_energy_a = std::abs(a.energy - w_exact) / w_exact;
  const double e_energy_rot_a = std::abs(a_rot.energy - a.energy) / a.energy;
  const double e_force_a = max_abs(a_rot.force - rotate(a.force, R)) / max_abs(a.force);
  std::printf(
      "objectivity (a) homogeneous F0: energy %.12g N mm, |E - W V|/W V = %.2e, |E_R - E|/E = %.2e, "
      "max|f_R - R f|/max|f| = %.2e\n",
      a.energy, e_energy_a, e_energy_rot_a, e_force_a);
  EXPECT_LT(e_energy_a, kRoundoff);
  EXPECT_LT(e_energy_rot_a, kRoundoff);
  EXPECT_LT(e_force_a, kRoundoff);

  // (b) Lateral boundary prescribed, faces free: Newton equilibrium, then rotated.
  // The rotated problem starts from the rigidly moved reference R X + t (stress free), so
  // its whole load path is the rotated image of the unrotated one (the solver moves
  // prescribed dofs linearly from start to target; from X itself the path to R F0 X + t
  // would pass through nearly collapsed states).
  const VecX X = model.reference_positions();
  const StaticResult b = solve(model, prescribe(model, xa, true), X);
  const StaticResult b_rot = solve(model, prescribe(model, xa_rot, true), rigid(X, R, t));
  ASSERT_TRUE(b.report.ok()) << b.report.brief();
  ASSERT_TRUE(b_rot.report.ok()) << b_rot.report.brief();
  const double eb = model.assemble(b.positions, false).energy;
  const double eb_rot = model.assemble(b_rot.positions, false).energy;
  const double e_energy_b = std::abs(eb_rot - eb) / eb;
  const double e_pos_b = max_abs(b_rot.positions - rigid(b.positions, R, t)) / max_abs(b.positions);
  const double e_react_b = max_abs(b_rot.reactions - rotate(b.reactions, R)) / max_abs(b.reactions);
  // The free faces make this state inhomogeneous: how far from F0 it is.
  double dev = 0.0;
  for (const Mat3& F : model.deformation_gradients(0, b.positions)) dev = std::max(dev, (F - F0).cwiseAbs().maxCoeff());
  std::printf(
      "objectivity (b) lateral boundary F0, faces free (%s; max|F - F0| = %.3f): energy %.12g N mm, "
      "|E_R - E|/E = %.2e, max|x_R - (R x + t)|/max|x| = %.2e, max|r_R - R r|/max|r| = %.2e\n",
      b.report.brief().c_str(), dev, eb, e_energy_b, e_pos_b, e_react_b);
  EXPECT_LT(e_energy_b, kRoundoff);
  EXPECT_LT(e_pos_b, kRoundoff);
  // Reactions come from a converged Newton state: the free-dof residual (<= 1e-13 of
  // the force scale) bounds how well the two solves agree.
  EXPECT_LT(e_react_b, 1e-10);
}

TEST(VerificationSimpleShear, AlongFibresGivesLongitudinalShearModulus) {
  const double L1 = 2.0, L2 = 2.0, h = 0.5;
  const TransverselyIsotropicParams params = ti_params();
  const double G_L = small_strain_moduli(params).G_L;
  ASSERT_DOUBLE_EQ(G_L, params.mu_L);
  PlyMesh ply0(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), L1, L2, 3, 3), h, 0.0);
  Model model;
  model.add_ply(ply0, std::make_shared<TransverselyIsotropic>(params, ply0.fibre_direction()));
  const PlyMesh& ply = model.ply(0);
  ASSERT_LT((ply.fibre_direction() - Vec3::UnitX()).norm(), 1e-15);

  for (double gamma : {1e-3, 0.5}) {
    Mat3 F = Mat3::Identity();
    F(0, 1) = gamma;
    const VecX exact = affine(ply, F, Vec3::Zero());
    const StaticResult res = solve(model, prescribe(model, exact, true), model.reference_positions());
    ASSERT_TRUE(res.report.ok()) << res.report.brief();
    const double e_pos = max_abs(res.positions - exact);

    // Shear force on the face y = L2 (value parameters of its nodes, both layers).
    double fx = 0.0;
    for (Index s = 0; s < ply.n_surface_nodes(); ++s) {
      if (std::abs(ply.surface().node_position(s).y() - L2) > 1e-12) continue;
      for (int layer = 0; layer < 2; ++layer) fx += res.reactions(model.dof(0, ply.node(s, layer), mesh::kValue, 0));
    }
    const double tau = fx / (L1 * h);
    // Mean first Piola-Kirchhoff stress from the virial of all reactions.
    const MatX X = ply.reference();
    const MatX r = PlyMesh::unflatten(res.reactions);
    const Mat3 P = r.transpose() * X / (L1 * L2 * h);
    Mat3 P_exact = Mat3::Zero();
    P_exact(0, 0) = (params.mu_L - params.mu_T) * gamma * gamma;
    P_exact(0, 1) = P_exact(1, 0) = params.mu_L * gamma;
    const double e_tau = std::abs(tau - G_L * gamma) / (G_L * gamma);
    const double e_P = (P - P_exact).cwiseAbs().maxCoeff() / (G_L * gamma);
    std::printf(
        "simple shear gamma = %g: tau = %.15g MPa, G_L gamma = %.15g MPa, rel. error %.2e; "
        "tau/gamma = %.12g (G_L = %g); max|P - P_exact|/(G_L gamma) = %.2e; max|x - x_exact| = %.2e mm (%s)\n",
        gamma, tau, G_L * gamma, e_tau, tau / gamma, G_L, e_P, e_pos, res.report.brief().c_str());
    EXPECT_LT(e_tau, 1e-10);
    EXPECT_LT(e_P, 1e-10);
    EXPECT_LT(e_pos, 1e-12);
  }
}

}  // namespace
}  // namespace sf::forming
