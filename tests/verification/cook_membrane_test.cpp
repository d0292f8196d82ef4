// Cook's membrane at finite strain (notes/forming-verification.md section 2.2; the
// deal.II code-gallery "Quasi-static finite-strain compressible elasticity" case):
//
//   tapered panel, corners (0,0), (48,44), (48,60), (0,44) mm, thickness 1 mm;
//   clamped at x = 0; dead uniform traction along +y on the face x = 48 (16 mm x 1 mm)
//   with total force 1 N, i.e. 1/16 N/mm^2; plane strain; output u_y at C = (48, 60).
//   Reference (deal.II, Q2 at 32 and 64 elements per edge): u_y(C) = 14.33 mm. NOTE: the
//   reference program does not actually apply u_z = 0 (see the test below): 14.33 is the
//   1 mm slab with free faces; the plane-strain value is reported separately (13.77).
//
// Units: the reference uses mu = 422.5 kPa with geometry in mm and force in N. In the
// library's N, mm, MPa set: mu = 0.4225 MPa, traction 0.0625 MPa.
//
// Material: the reference's compressible neo-Hookean is not the library's NeoHookean
// (forming/material/neo_hookean.hpp: W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2); deal.II uses
//   W = kappa/4 (J^2 - 1 - 2 ln J) + mu/2 (J^(-2/3) I1 - 3),
//   kappa = 2 mu (1 + nu) / (3 (1 - 2 nu)),
// which has the same small-strain moduli but differs at finite strain. To follow the
// reference exactly the test implements that energy as a forming::Material here
// (DealiiNeoHookean below, checked against finite differences), and also reports what
// the library's NeoHookean (same mu, nu) gives.
//   S  = kappa/2 (J^2 - 1) Ci + mu J^(-2/3) (I - I1/3 Ci)
//   CC = kappa J^2 Ci (x) Ci - kappa (J^2 - 1) (Ci (.) Ci)
//        + (2a/3) [ -(I (x) Ci + Ci (x) I) + I1/3 Ci (x) Ci + I1 (Ci (.) Ci) ],  a = mu J^(-2/3).
//
// Discretisation: n x n bricks (one through the thickness) on the bilinear map of the
// corners (mesh_from_corners). Plane strain (Faces::kPlaneStrain): the z coordinate of every parameter of every
// node (both faces) is held at its reference value (values 0 and 1, derivatives 0), so
// x, y do not depend on z and F_33 = 1. Clamp at x = 0: every parameter (value, d/ds1,
// d/ds2, d2/ds1ds2) of the edge nodes, both layers (Clamp::kAllParameters), or only the
// value and the along-wall tangent d/ds2 (Clamp::kValueAndTangent). For a continuum the
// first also fixes d/ds1 (the normal derivative), i.e. du/dx = 0 on the wall, which is
// stiffer than u = 0 alone; the second is the continuum Dirichlet condition u = 0 for
// Hermite parameters and is the one asserted against the reference.
//
// Load: consistent generalised forces of the uniform traction on the face x = 48
// (straight edge, unit d/ds2 tangents, scale factor S = element edge length le):
// q = 1/16 N/mm along the edge over the whole thickness, each layer half; per element
// edge, value a, b: q le/2; d/ds2 of a: +q S le/12; of b: -q S le/12 (Hermite integrals
// 1/2, 1/12, 1/2, -1/12); the cross-edge and cross derivative functions vanish on it.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <string>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "common/mesh/surface_mesh.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_mesh.hpp"
#include "forming/solve/static_solver.hpp"

namespace sf::forming {
namespace {

constexpr double kMu = 0.4225;  // MPa (422.5 kPa)
constexpr double kNu = 0.3;
constexpr double kReference = 14.33;      // mm, deal.II Q2 at 32-64 elements per edge
constexpr double kTraction = 1.0 / 16.0;  // MPa (1 N over 16 mm x 1 mm)

constexpr int kVoigt[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

// deal.II code-gallery compressible neo-Hookean (see header).
class DealiiNeoHookean final : public Material {
 public:
  DealiiNeoHookean(double mu, double nu) : mu_(mu), kappa_(2.0 * mu * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))) {}
  MaterialResponse evaluate(const Mat3& C, bool want_tangent) const override {
    MaterialResponse r;
    const double det = C.determinant();
    if (!(det > 0.0)) {
      r.energy = std::numeric_limits<double>::infinity();
      r.stress.setConstant(std::numeric_limits<double>::quiet_NaN());
      r.tangent.setConstant(std::numeric_limits<double>::quiet_NaN());
      return r;
    }
    const double J = std::sqrt(det), J2 = det;
    const double I1 = C.trace();
    const double a = mu_ * std::pow(J, -2.0 / 3.0);
    const Mat3 Ci = C.inverse();
    const Mat3 I = Mat3::Identity();
    r.energy = 0.25 * kappa_ * (J2 - 1.0 - 2.0 * std::log(J)) + 0.5 * (a * I1 - 3.0 * mu_);
    r.stress = 0.5 * kappa_ * (J2 - 1.0) * Ci + a * (I - I1 / 3.0 * Ci);
    if (want_tangent) {
      for (int p = 0; p < 6; ++p)
        for (int q = 0; q < 6; ++q) {
          const int i = kVoigt[p][0], j = kVoigt[p][1], k = kVoigt[q][0], l = kVoigt[q][1];
          const double cc = Ci(i, j) * Ci(k, l);
          const double codot = 0.5 * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k));
          const double mixed = I(i, j) * Ci(k, l) + Ci(i, j) * I(k, l);
          r.tangent(p, q) =
              kappa_ * J2 * cc - kappa_ * (J2 - 1.0) * codot + (2.0 * a / 3.0) * (-mixed + I1 / 3.0 * cc + I1 * codot);
        }
    }
    return r;
  }
  std::string name() const override { return "deal.II compressible neo-Hookean"; }

 private:
  double mu_, kappa_;
};

TEST(VerificationCook, DealiiMaterialMatchesFiniteDifferences) {
  const DealiiNeoHookean m(kMu, kNu);
  Mat3 F;
  F << 1.3, 0.2, -0.1,  //
      0.1, 0.8, 0.15,   //
      -0.05, 0.1, 1.1;
  const Mat3 C = F.transpose() * F;
  const MaterialResponse r = m.evaluate(C, true);
  const double h = 1e-6;
  double e_s = 0.0, e_cc = 0.0;
  for (int p = 0; p < 6; ++p) {
    const int i = kVoigt[p][0], j = kVoigt[p][1];
    Mat3 dC = Mat3::Zero();
    dC(i, j) += h;
    if (i != j) dC(j, i) += h;
    const MaterialResponse rp = m.evaluate(C + dC, false), rm = m.evaluate(C - dC, false);
    // S_ij = 2 dW/dC_ij: a symmetric perturbation of both (i,j) and (j,i) doubles the derivative.
    const double s_fd = (rp.energy - rm.energy) / (2.0 * h) * (i == j ? 2.0 : 1.0);
    e_s = std::max(e_s, std::abs(s_fd - r.stress(i, j)));
    // CC_.. p-column = dS/dE_p with dE = dC/2 (shear entries in voigt_strain form).
    const Mat3 dS = (rp.stress - rm.stress) / (2.0 * h) * 2.0;
    for (int q = 0; q < 6; ++q) {
      const double fd = dS(kVoigt[q][0], kVoigt[q][1]) * (i == j ? 1.0 : 0.5);
      e_cc = std::max(e_cc, std::abs(fd - r.tangent(q, p)));
    }
  }
  std::printf("deal.II neo-Hookean: max |S - FD| = %.2e MPa, max |CC - FD| = %.2e MPa (mu = %g MPa)\n", e_s, e_cc, kMu);
  EXPECT_LT(e_s, 1e-8);
  EXPECT_LT(e_cc, 1e-7);
  // Small-strain limit: lambda, mu of E, nu.
  const MaterialResponse r0 = m.evaluate(Mat3::Identity(), true);
  const double lambda = 2.0 * kMu * kNu / (1.0 - 2.0 * kNu);
  EXPECT_NEAR(r0.tangent(0, 0), lambda + 2.0 * kMu, 1e-12);
  EXPECT_NEAR(r0.tangent(0, 1), lambda, 1e-12);
  EXPECT_NEAR(r0.tangent(3, 3), kMu, 1e-12);
  EXPECT_LT(r0.stress.norm(), 1e-15);
}

enum class Clamp { kAllParameters, kValueAndTangent };
// kPlaneStrain: z of every parameter held (the brief / notes' statement of the case);
// kFreeFaces: faces z = 0, 1 free (what the reference code actually computes, see the test).
enum class Faces { kPlaneStrain, kFreeFaces };

struct CookResult {
  double uy = 0.0;
  double seconds = 0.0;
  Index n_dofs = 0;
  std::string brief;
  bool ok = false;
};

CookResult solve_cook(int n, std::shared_ptr<const Material> material, Clamp clamp, Faces faces) {
  const auto t0 = std::chrono::steady_clock::now();
  Points3 nodes((n + 1) * (n + 1), 3);
  auto id = [n](int i, int j) { return static_cast<Index>(j) * (n + 1) + i; };
  const Vec2 P00(0, 0), P10(48, 44), P01(0, 44), P11(48, 60);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double s = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
      const Vec2 p = (1 - s) * (1 - t) * P00 + s * (1 - t) * P10 + (1 - s) * t * P01 + s * t * P11;
      nodes.row(id(i, j)) << p.x(), p.y(), 0.0;
    }
  std::vector<std::array<Index, 4>> elements;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) elements.push_back({id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});
  Model model;
  model.add_ply(PlyMesh(mesh::mesh_from_corners(nodes, elements, "cook"), 1.0, 0.0), std::move(material));
  const PlyMesh& ply = model.ply(0);
  const mesh::SurfaceMesh& surf = ply.surface();
  const VecX X = model.reference_positions();

  std::vector<PrescribedDof> bcs;
  std::vector<bool> fixed(model.n_dofs(), false);
  auto hold = [&](Index dof) {
    if (fixed[dof]) return;
    fixed[dof] = true;
    bcs.push_back({dof, X(dof)});
  };
  for (Index s = 0; s < surf.n_nodes(); ++s) {
    const bool wall = std::abs(surf.node_position(s).x()) < 1e-9;
    for (int layer = 0; layer < 2; ++layer)
      for (int d = 0; d < 4; ++d) {
        if (faces == Faces::kPlaneStrain) hold(model.dof(0, ply.node(s, layer), d, 2));
        const bool clamp_d = clamp == Clamp::kAllParameters || d == mesh::kValue || d == mesh::kD2;
        if (wall && clamp_d)
          for (int i = 0; i < 3; ++i) hold(model.dof(0, ply.node(s, layer), d, i));
      }
  }

  // Consistent loads on the face x = 48 (see header).
  VecX f = VecX::Zero(model.n_dofs());
  const double q = kTraction * 1.0;  // N/mm of edge (thickness 1 mm)
  for (const auto& [e, edge] : surf.boundary_edges()) {
    const mesh::Element& el = surf.element(e);
    const std::array<int, 2> ln = mesh::edge_local_nodes(edge);
    const Index a = el.nodes[ln[0]], b = el.nodes[ln[1]];
    if (std::abs(surf.node_position(a).x() - 48.0) > 1e-9 || std::abs(surf.node_position(b).x() - 48.0) > 1e-9)
      continue;
    EXPECT_TRUE(edge == 1 || edge == 3);  // the xi2 direction runs along x = 48
    const double le = (surf.node_position(b) - surf.node_position(a)).norm();
    for (int layer = 0; layer < 2; ++layer) {
      f(model.dof(0, ply.node(a, layer), mesh::kValue, 1)) += 0.5 * q * le / 2.0;
      f(model.dof(0, ply.node(b, layer), mesh::kValue, 1)) += 0.5 * q * le / 2.0;
      f(model.dof(0, ply.node(a, layer), mesh::kD2, 1)) += 0.5 * q * el.scale[ln[0]][1] * le / 12.0;
      f(model.dof(0, ply.node(b, layer), mesh::kD2, 1)) -= 0.5 * q * el.scale[ln[1]][1] * le / 12.0;
      // The along-edge tangent parameters are (0, 1, 0) (mesh_from_corners: unit edge direction).
      EXPECT_NEAR(X(model.dof(0, ply.node(a, layer), mesh::kD2, 1)), 1.0, 1e-12);
    }
  }
  EXPECT_NEAR(f.sum(), 1.0, 1e-12);

  StaticOptions o;
  o.initial_increment = 0.25;
  o.max_increment = 0.5;
  const StaticResult res = solve_static(model, X, bcs, f, o);
  CookResult out;
  out.ok = res.report.ok();
  out.brief = res.report.brief();
  out.n_dofs = model.n_dofs();
  const Index c = id(n, n);
  EXPECT_NEAR(surf.node_position(c).y(), 60.0, 1e-12);
  out.uy = 0.5 * (res.positions(model.dof(0, ply.node(c, 0), mesh::kValue, 1)) +
                  res.positions(model.dof(0, ply.node(c, 1), mesh::kValue, 1))) -
           60.0;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

// Which problem the reference solved: the deal.II gallery program (cook_membrane.cc, 3-D
// run: its Q1 dof counts 24, 54, ... are 3 x nodes of n x n x 1 hexahedra) tags the
// "+Z and -Z faces" for the u_z = 0 constraint with |center()[0]| - 0.5 (the x
// coordinate, not z), so no face gets the tag and u_z stays free: the published 14.33 is
// the 1 mm slab with traction-free faces, not plane strain. This test therefore asserts
// the free-face case against 14.33, and reports the plane-strain case (u_z = 0 on both
// faces, as the brief and the notes state it), which converges to a ~4 % stiffer 13.77.
TEST(VerificationCook, FiniteStrainTipDisplacementConvergesToReference) {
  auto dealii = std::make_shared<DealiiNeoHookean>(kMu, kNu);
  const double lambda = 2.0 * kMu * kNu / (1.0 - 2.0 * kNu);
  auto library = std::make_shared<NeoHookean>(NeoHookeanParams{kMu, lambda});
  // Tolerance on the finest mesh (16 x 16) against the converged reference 14.33.
  constexpr double kTol = 5e-3;
  // Clamp = value + d/ds2 of the wall nodes (u = 0 on the wall: the continuum condition).
  double finest = 0.0;
  for (int n : {2, 4, 8, 16}) {
    const CookResult r = solve_cook(n, dealii, Clamp::kValueAndTangent, Faces::kFreeFaces);
    ASSERT_TRUE(r.ok) << n << ": " << r.brief;
    std::printf(
        "cook %2d x %-2d (%5ld dofs), faces free, value + d/ds2 clamp: u_y(C) = %.4f mm, rel. error vs %.2f = "
        "%+.2e; %s; %.2f s\n",
        n, n, static_cast<long>(r.n_dofs), r.uy, kReference, (r.uy - kReference) / kReference, r.brief.c_str(),
        r.seconds);
    finest = r.uy;
  }
  EXPECT_LT(std::abs(finest - kReference) / kReference, kTol);
  // Clamp = every parameter of the wall nodes (the brief's definition): also du/dx = 0 at
  // the wall, a one-element boundary layer that is stiffer and converges at first order
  // (measured 13.24, 13.84, 14.09, 14.21 at 2, 4, 8, 16 elements per edge).
  {
    const CookResult r = solve_cook(16, dealii, Clamp::kAllParameters, Faces::kFreeFaces);
    ASSERT_TRUE(r.ok) << r.brief;
    std::printf("cook 16 x 16, faces free, all-parameter clamp: u_y(C) = %.4f mm, rel. error %+.2e; %.2f s\n", r.uy,
                (r.uy - kReference) / kReference, r.seconds);
    EXPECT_LT(std::abs(r.uy - kReference) / kReference, 1e-2);
  }
  double ps8 = 0.0, ps16 = 0.0;
  for (int n : {8, 16}) {
    const CookResult r = solve_cook(n, dealii, Clamp::kValueAndTangent, Faces::kPlaneStrain);
    ASSERT_TRUE(r.ok) << n << ": " << r.brief;
    std::printf(
        "cook %2d x %-2d, plane strain (u_z = 0), value + d/ds2 clamp: u_y(C) = %.4f mm (%+.2e vs 14.33); "
        "%.2f s\n",
        n, n, r.uy, (r.uy - kReference) / kReference, r.seconds);
    (n == 8 ? ps8 : ps16) = r.uy;
  }
  // Plane strain: converged to 0.1 % between 8 and 16 elements per edge (measured 4e-4).
  EXPECT_LT(std::abs(ps16 - ps8) / ps16, 1e-3);
  {
    const CookResult r = solve_cook(8, library, Clamp::kAllParameters, Faces::kFreeFaces);
    ASSERT_TRUE(r.ok) << r.brief;
    std::printf(
        "cook 8 x 8, faces free, library NeoHookean (ln J form, same mu, nu): u_y(C) = %.4f mm (%+.2e vs "
        "14.33); %.2f s\n",
        r.uy, (r.uy - kReference) / kReference, r.seconds);
  }
}

}  // namespace
}  // namespace sf::forming
