// Large-deflection bending of a thin ply strip (notes/forming-verification.md sections
// 1.4 and 2.3): the Hermite in-plane interpolation and the initial-stress matrix.
//
// Strip: L = 100 mm along x, b = 10 mm along y, h = 1 mm along z, mid-surface at z = 0
// (PlyPlacement::kMiddle), 20 x 1 bricks. Compressible neo-Hookean with lambda = 0, i.e.
// nu = 0 and E = 2 mu = 1000 MPa, so at small strain the bending stiffness is exactly
// EI = E b h^3 / 12 with no anticlastic (Poisson) curvature across the width. Clamp at
// x = 0: the section, i.e. values and the along-edge tangent d/ds2 of the root nodes, both
// layers (u = 0 on the face; the continuum clamp). Holding every parameter (d/ds1 too)
// also imposes zero fibre strain at the root, where the moment is largest: measured 2.5 %
// too stiff at alpha = 1 with 20 elements (0.96 % with 40, 0.41 % with 80); reported.
//
//  * Elastica: dead tip load P e3 spread as a uniform traction over the tip face, as
//    consistent generalised forces (see edge_load()); tip deflection v and shortening u
//    of the mid-surface (mean of the tip nodes of both layers) against the table of
//    section 1.4 for alpha = P L^2 / EI = 1, 3, 5, 10.
//    Differences from the Euler elastica: transverse shear (3 E I / (kappa G A L^2) =
//    6e-5 here), the finite bending strain (h/2 x curvature <= 0.03 at the root for
//    alpha = 10: the neo-Hookean moment-curvature law deviates from linear at second
//    order), and discretisation. Measured errors are printed.
//
//  * End-rotation roll-up: pure bending makes the mid-surface a circular arc of radius
//    R = L / theta centred at (0, y, R), tip at (R sin theta, y, R (1 - cos theta)),
//    bending energy EI theta^2 / (2 L); theta = pi/4, pi/2, pi, 2 pi (closed circle;
//    self-contact not modelled). Asserted form: the root and tip SECTIONS are placed on
//    the exact field (values and d/ds2), the interior is free. The brief's form (only
//    d/ds1 of the tip nodes prescribed to (cos theta, 0, sin theta), tip positions free)
//    is not a section rotation for a continuum (the tip section shears; the error grows
//    with refinement): reported in a second test.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
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

constexpr double kL = 100.0, kB = 10.0, kH = 1.0;
constexpr double kMu = 500.0;  // MPa; lambda = 0 -> E = 2 mu, nu = 0
constexpr double kE = 2.0 * kMu;
constexpr double kEI = kE * kB * kH * kH * kH / 12.0;  // N mm^2
constexpr int kElementsAlong = 20;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Model make_strip(int n_along = kElementsAlong) {
  return fixtures::one_ply_model(fixtures::rectangle_ply(kL, kB, kH, n_along, 1, 0.0, PlyPlacement::kMiddle),
                                 fixtures::neo_hookean(kMu, 0.0));
}

using fixtures::Held;
using fixtures::surface_nodes_at_x;

// Section of the nodes at x held at `target` (both layers): kSection = values and the
// along-edge tangent d/ds2 (the continuum Dirichlet condition: u given on the face);
// kAllParameters also holds d/ds1 and d2/ds1ds2, i.e. additionally du/dx on the face,
// which forces zero fibre strain there (over-constrains a bent section).
std::vector<PrescribedDof> hold_nodes(const Model& model, double x, const VecX& X, Held held) {
  return fixtures::held_at(fixtures::node_dofs(model, 0, surface_nodes_at_x(model.ply(0), x), held), X);
}
std::vector<PrescribedDof> clamp_root(const Model& model, Held held = Held::kAllParameters) {
  return hold_nodes(model, 0.0, model.reference_positions(), held);
}

// Consistent generalised forces of a uniform dead traction on the lateral faces over
// the free surface edges whose two nodes are at x = x_edge: q = force per unit edge
// length (N/mm) over the whole thickness. Through the thickness the linear functions
// give each layer half. Along a straight edge of length le, with nodes a (t = 0) and b
// (t = 1) and unit tangent parameters with scale factor S (the element map's S times
// the arc-length parameter), the Hermite functions integrate to
//   value a, b: le/2 each;   derivative a: +S le/12;   derivative b: -S le/12
// (int_0^1 H0 = H2 = 1/2, H1 = 1/12, H3 = -1/12); the other parameters' functions
// (cross-edge derivative, cross derivative) vanish on the edge. Interior edge nodes get
// the derivative terms of both neighbours, which cancel for equal lengths.
VecX edge_load(const Model& model, double x_edge, const Vec3& q) {
  const PlyMesh& ply = model.ply(0);
  const mesh::SurfaceMesh& s = ply.surface();
  VecX f = VecX::Zero(model.n_dofs());
  for (const auto& [e, edge] : s.boundary_edges()) {
    const mesh::Element& el = s.element(e);
    const std::array<int, 2> ln = mesh::edge_local_nodes(edge);
    const Index a = el.nodes[ln[0]], b = el.nodes[ln[1]];
    if (std::abs(s.node_position(a).x() - x_edge) > 1e-9 || std::abs(s.node_position(b).x() - x_edge) > 1e-9) continue;
    const int dir = (edge == 0 || edge == 2) ? 0 : 1;
    const int d = dir == 0 ? mesh::kD1 : mesh::kD2;
    const double le = (s.node_position(b) - s.node_position(a)).norm();
    for (int layer = 0; layer < 2; ++layer)
      for (int i = 0; i < 3; ++i) {
        f(model.dof(0, ply.node(a, layer), mesh::kValue, i)) += 0.5 * q(i) * le / 2.0;
        f(model.dof(0, ply.node(b, layer), mesh::kValue, i)) += 0.5 * q(i) * le / 2.0;
        f(model.dof(0, ply.node(a, layer), d, i)) += 0.5 * q(i) * el.scale[ln[0]][dir] * le / 12.0;
        f(model.dof(0, ply.node(b, layer), d, i)) -= 0.5 * q(i) * el.scale[ln[1]][dir] * le / 12.0;
      }
  }
  return f;
}

// Mean position of the value parameters of the given surface nodes, both layers
// (with kMiddle placement: the mid-surface).
Vec3 mean_position(const Model& model, const VecX& x, const std::vector<Index>& nodes) {
  const PlyMesh& ply = model.ply(0);
  Vec3 m = Vec3::Zero();
  for (Index s : nodes)
    for (int layer = 0; layer < 2; ++layer)
      for (int i = 0; i < 3; ++i) m(i) += x(model.dof(0, ply.node(s, layer), mesh::kValue, i));
  return m / (2.0 * static_cast<double>(nodes.size()));
}

struct ElasticaRow {
  double alpha, v, u;  // notes section 1.4 (v/L, u/L)
};

double solve_elastica(const Model& model, const std::vector<PrescribedDof>& bcs, const ElasticaRow& row, double tol_v,
                      double tol_u, const char* label) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Index> tip = surface_nodes_at_x(model.ply(0), kL);
  const double P = row.alpha * kEI / (kL * kL);
  const VecX f = edge_load(model, kL, Vec3(0.0, 0.0, P / kB));
  EXPECT_NEAR(f.sum(), P, 1e-12 * P);  // value forces sum to P, derivative terms cancel
  StaticOptions o;
  o.initial_increment = 0.1;
  o.max_increment = 0.25;
  const StaticResult res = solve_static(model, model.reference_positions(), bcs, f, o);
  EXPECT_TRUE(res.report.ok()) << res.report.brief();
  const Vec3 m = mean_position(model, res.positions, tip);
  const double v = m.z() / kL, u = (kL - m.x()) / kL;
  const double ev = (v - row.v) / row.v, eu = (u - row.u) / row.u;
  std::printf(
      "elastica %s, alpha = %4.1f: v/L = %.5f (table %.5f, rel. error %+.2e), u/L = %.5f (table %.5f, rel. "
      "error %+.2e); %s; %.2f s\n",
      label, row.alpha, v, row.v, ev, u, row.u, eu, res.report.brief().c_str(), seconds_since(t0));
  EXPECT_LT(std::abs(ev), tol_v) << label << " alpha " << row.alpha;
  EXPECT_LT(std::abs(eu), tol_u) << label << " alpha " << row.alpha;
  return ev;
}

TEST(VerificationElastica, TipLoadedCantileverMatchesEulerElastica) {
  const Model model = make_strip();
  // Root clamp = the section (values and d/ds2 of the root nodes): the continuum clamp.
  const std::vector<PrescribedDof> bcs = clamp_root(model, Held::kSection);
  // Relative tolerances on v/L and u/L (measured errors printed; see the file header).
  constexpr double kTolV = 5e-3, kTolU = 1e-2;
  // alpha = 5 and 10 also pass (+1.1e-4 / +1.5e-4 on v) but take 8 s each: left out.
  for (const ElasticaRow& row : {ElasticaRow{1.0, 0.30172, 0.05643}, ElasticaRow{3.0, 0.60325, 0.25442}})
    solve_elastica(model, bcs, row, kTolV, kTolU, "section clamp");
  // Every root parameter held (d/ds1 too: zero fibre strain at the root, where the moment
  // is largest): stiffer by a boundary layer of one element; measured at alpha = 1:
  // v 2.5 % low with 20 elements, 0.96 % with 40, 0.41 % with 80 (first order in the
  // element length). Asserted loosely, to show the trend's sign and size.
  const double ev = solve_elastica(model, clamp_root(model, Held::kAllParameters), ElasticaRow{1.0, 0.30172, 0.05643},
                                   3e-2, 5e-2, "all-parameter clamp");
  EXPECT_LT(ev, 0.0);
}

// Mid-surface points (mean of the two layers) along every xi1 line: at the nodes and at
// element midpoints (cubic Hermite in s1: H0 = H2 = 1/2, H1 = -H3 = 1/8 at t = 1/2).
std::vector<Vec3> mid_surface_points(const Model& model, const VecX& x) {
  const PlyMesh& ply = model.ply(0);
  const mesh::SurfaceMesh& s = ply.surface();
  auto mid = [&](Index node, int d) {
    Vec3 m;
    for (int i = 0; i < 3; ++i)
      m(i) = 0.5 * (x(model.dof(0, ply.node(node, 0), d, i)) + x(model.dof(0, ply.node(node, 1), d, i)));
    return m;
  };
  std::vector<Vec3> pts;
  for (Index node = 0; node < s.n_nodes(); ++node) pts.push_back(mid(node, mesh::kValue));
  for (Index e = 0; e < s.n_elements(); ++e) {
    const mesh::Element& el = s.element(e);
    for (int pair = 0; pair < 2; ++pair) {  // edges xi2 = 0 (nodes 0-1) and xi2 = 1 (2-3)
      const int la = 2 * pair, lb = 2 * pair + 1;
      const Index a = el.nodes[la], b = el.nodes[lb];
      pts.push_back(0.5 * (mid(a, mesh::kValue) + mid(b, mesh::kValue)) +
                    0.125 * (el.scale[la][0] * mid(a, mesh::kD1) - el.scale[lb][0] * mid(b, mesh::kD1)));
    }
  }
  return pts;
}

// Exact pure-bending field of the strip rolled to angle theta (R = L / theta): a point at
// arc length s = X, height zeta = Z from the mid-surface goes to
//   (0, Y, R) + (R - zeta) (sin(s/R), 0, -cos(s/R)),
// so d/ds1 = (1 - zeta/R) (cos(s/R), 0, sin(s/R)), d/ds2 = e2, d2/ds1ds2 = 0.
VecX rolled(const Model& model, double theta) {
  const PlyMesh& ply = model.ply(0);
  MatX x = ply.reference();
  const double R = kL / theta;
  for (Index n = 0; n < ply.n_nodes(); ++n) {
    const Vec3 X = ply.reference().row(PlyMesh::param(n, mesh::kValue)).transpose();
    const double phi = X.x() / R, zeta = X.z();
    x.row(PlyMesh::param(n, mesh::kValue)) << (R - zeta) * std::sin(phi), X.y(), R - (R - zeta) * std::cos(phi);
    x.row(PlyMesh::param(n, mesh::kD1)) << (1.0 - zeta / R) * std::cos(phi), 0.0, (1.0 - zeta / R) * std::sin(phi);
    x.row(PlyMesh::param(n, mesh::kD2)) << 0.0, 1.0, 0.0;
    x.row(PlyMesh::param(n, mesh::kD12)).setZero();
  }
  return PlyMesh::flatten(x);
}

struct RollUpCheck {
  double e_tip = 0.0, e_arc = 0.0, e_energy = 0.0, energy = 0.0, exact = 0.0;
  Vec3 tip = Vec3::Zero();
};

RollUpCheck check_roll_up(const Model& model, const VecX& x, double theta) {
  const std::vector<Index> tip = surface_nodes_at_x(model.ply(0), kL);
  const double R = kL / theta;
  RollUpCheck c;
  c.tip = mean_position(model, x, tip);
  c.e_tip = std::hypot(c.tip.x() - R * std::sin(theta), c.tip.z() - R * (1.0 - std::cos(theta))) / kL;
  for (const Vec3& p : mid_surface_points(model, x))
    c.e_arc = std::max(c.e_arc, std::abs(std::hypot(p.x(), p.z() - R) - R) / kL);
  c.energy = model.assemble(x, false).energy;
  c.exact = kEI * theta * theta / (2.0 * kL);
  c.e_energy = std::abs(c.energy - c.exact) / c.exact;
  return c;
}

// Root and tip sections held on the exact field (values and d/ds2 of their nodes, both
// layers: the section is placed, the fibre stretch at the ends is left free): the
// interior must follow the arc, the energy must be EI theta^2 / (2L) and the tip
// reaction a pure couple (resultant force ~ 0).
TEST(VerificationRollUp, EndRotationBendsStripIntoCircularArc) {
  const Model model = make_strip();
  const PlyMesh& ply = model.ply(0);
  const std::vector<Index> tip = surface_nodes_at_x(ply, kL);
  // Tolerances: arc deviation relative to L, energy relative to EI theta^2 / (2L), tip
  // resultant force relative to the couple's force M / h (measured: <= 5.5e-5, 3.2e-4,
  // 3.8e-5; the energy difference grows like theta^2, the finite-strain correction).
  constexpr double kTolArc = 1e-4, kTolEnergy = 1e-3, kTolForce = 1e-3;
  // Each angle is solved from the exact field itself (prescribed dofs already at their
  // targets, so Newton only corrects the free interior): moving the ends there from the
  // straight strip along straight lines would compress the strip along the chord and
  // buckle it.
  const auto t0 = std::chrono::steady_clock::now();
  for (double turns : {0.125, 0.25, 0.5, 1.0}) {
    const double theta = 2.0 * kPi * turns;
    const VecX target = rolled(model, theta);
    std::vector<PrescribedDof> bcs = hold_nodes(model, 0.0, target, Held::kSection);
    const std::vector<PrescribedDof> tip_bcs = hold_nodes(model, kL, target, Held::kSection);
    bcs.insert(bcs.end(), tip_bcs.begin(), tip_bcs.end());
    const StaticResult res = solve_static(model, target, bcs, VecX());
    ASSERT_TRUE(res.report.ok()) << "theta " << theta << ": " << res.report.brief();
    const VecX& x = res.positions;
    const RollUpCheck c = check_roll_up(model, x, theta);
    Vec3 force = Vec3::Zero();
    for (Index s : tip)
      for (int layer = 0; layer < 2; ++layer)
        for (int i = 0; i < 3; ++i) force(i) += res.reactions(model.dof(0, ply.node(s, layer), mesh::kValue, i));
    const double couple_force = kEI * theta / kL / kH;  // M / h
    const double e_force = force.norm() / couple_force;
    std::printf(
        "roll-up (tip section on the circle) theta = %g pi: max mid-surface deviation from the circle / L = "
        "%.2e; energy %.6g vs EI theta^2/2L = %.6g N mm (rel. error %+.2e); |tip resultant| / (M/h) = %.2e; "
        "%s; %.2f s so far\n",
        theta / kPi, c.e_arc, c.energy, c.exact, (c.energy - c.exact) / c.exact, e_force, res.report.brief().c_str(),
        seconds_since(t0));
    EXPECT_LT(c.e_arc, kTolArc) << "theta " << theta;
    EXPECT_LT(c.e_energy, kTolEnergy) << "theta " << theta;
    EXPECT_LT(e_force, kTolForce) << "theta " << theta;
  }
}

// The brief's variant: only d/ds1 of the tip nodes prescribed to (cos theta, 0, sin theta),
// tip positions free. For a continuum this edge-derivative constraint is not a section
// rotation: the tip section can shear, the strip bends less than the circle and the
// disturbance does not vanish with refinement (measured at theta = pi/2: tip error / L
// 3.3e-2 with 20 elements, 5.5e-2 with 40; energy 2.9 % and 7.0 % below EI theta^2/2L).
// Reported, not asserted against the circle.
TEST(VerificationRollUp, TangentOnlyEndRotationIsNotAPureMoment) {
  const Model model = make_strip();
  const PlyMesh& ply = model.ply(0);
  const std::vector<Index> tip = surface_nodes_at_x(ply, kL);
  VecX x = model.reference_positions();
  for (int k = 1; k <= 4; ++k) {  // to pi/2 in steps of pi/8
    const double theta = 0.5 * kPi * k / 4;
    std::vector<PrescribedDof> bcs = clamp_root(model);
    const Vec3 tangent(std::cos(theta), 0.0, std::sin(theta));
    for (Index s : tip)
      for (int layer = 0; layer < 2; ++layer)
        for (int i = 0; i < 3; ++i) bcs.push_back({model.dof(0, ply.node(s, layer), mesh::kD1, i), tangent(i)});
    const StaticResult res = solve_static(model, x, bcs, VecX());
    ASSERT_TRUE(res.report.ok()) << res.report.brief();
    x = res.positions;
  }
  const RollUpCheck c = check_roll_up(model, x, 0.5 * kPi);
  std::printf(
      "roll-up (tangent-only tip condition) theta = pi/2: tip (%.4f, %.4f) vs (%.4f, %.4f) mm, |error|/L = "
      "%.2e; max deviation from the circle / L = %.2e; energy rel. error %+.2e\n",
      c.tip.x(), c.tip.z(), kL / (0.5 * kPi), kL / (0.5 * kPi), c.e_tip, c.e_arc, (c.energy - c.exact) / c.exact);
  // The bent shape is a sanity bound only: the tip moved up and inwards by the right order.
  EXPECT_LT(c.e_tip, 0.1);
}

}  // namespace
}  // namespace sf::forming
