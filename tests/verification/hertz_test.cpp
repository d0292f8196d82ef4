// Hertz contact, small-load limit (docs/forming.md "Contact checks"): a rigid cylinder of
// radius R pressed on an elastic half-space in plane strain. With P the load per unit
// length and E* = E / (1 - nu^2) (rigid indenter), the contact half-width and the peak
// pressure are
//   a = sqrt(4 P R / (pi E*)),   p0 = 2 P / (pi a),   p(x) = p0 sqrt(1 - x^2 / a^2).
//
// The body. One ply has a single linear element through its thickness, far too coarse
// for the stress field under a contact. The body here is a ply turned on its side: its
// bicubic Hermite surface spans the x-z section (graded towards the contact: elements
// of size h over [0, 2a] in x and over the top 2a in z, growing by at most 1.5 to a
// 40a x 40a half-section), its one linear element through the thickness is the width
// along y, and every y parameter is held, u_y = 0: plane strain. Symmetry at x = 0,
// bottom clamped. The cylinder (axis along y) is lowered by a prescribed approach; the
// contact is the top side faces of the section (6 x 6 points a face) against the tool,
// augmented Lagrangian so the penalty's compliance does not enter.
//
// Measured: the contact points' pressure p(x); a and p0 from the least-squares line of
// p^2 against x^2 over the points with p > 0.3 p_max (p^2 = p0^2 - (p0/a)^2 x^2 is exact
// Hertz), P from the tool's reaction, compared with a and p0 of Hertz at that P.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <tuple>
#include <vector>

#include "common/mesh/surface_mesh.hpp"
#include "forming/contact/tool_contact.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/model/ply_grid.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/solve/stepper.hpp"

namespace sf::forming {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Breakpoints 0 .. length: n_fine elements of size h from 0, then sizes growing by at
// most `growth` (the last one stretched or shrunk to end at `length`).
std::vector<double> graded(double length, double h, int n_fine, double growth) {
  std::vector<double> b{0.0};
  for (int i = 0; i < n_fine; ++i) b.push_back(b.back() + h);
  double size = h;
  while (b.back() < length - 1e-12) {
    size *= growth;
    if (b.back() + 1.5 * size >= length) {
      b.push_back(length);
      break;
    }
    b.push_back(b.back() + size);
  }
  b.back() = length;
  return b;
}

struct HertzResult {
  double a = 0.0, p0 = 0.0;      // measured, mm and MPa
  double a_h = 0.0, p0_h = 0.0;  // Hertz at the measured load
  double load = 0.0;             // N/mm
  int elements = 0;
};

HertzResult hertz(int n_fine) {
  const double E = 100.0, nu = 0.3, R = 50.0;
  const double a_target = 0.5;
  const double L = 40.0 * a_target, D = 40.0 * a_target, w = 0.01;  // mm
  const double h = 2.0 * a_target / n_fine;
  const std::vector<double> bx = graded(L, h, n_fine, 1.5);
  std::vector<double> bz = graded(D, h, n_fine, 1.5);  // fine at z = D: mirror it
  {
    std::vector<double> m;
    for (auto it = bz.rbegin(); it != bz.rend(); ++it) m.push_back(D - *it);
    bz = m;
  }
  const int n1 = static_cast<int>(bx.size()) - 1, n2 = static_cast<int>(bz.size()) - 1;
  // Surface directions x (s1) and z (s2): the ply normal x cross z = -y, the width.
  PlyMesh ply(mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), L, D, n1, n2, bx, bz), w, 0.0);
  Problem problem;
  problem.model.add_ply(std::move(ply), std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(E, nu)));
  const Model& model = problem.model;
  const PlyGrid grid{n1, n2};

  // Symmetry at x = 0 (grid side x0), clamp at z = 0 (grid side y0), u_y = 0 everywhere.
  EdgeCondition sym;
  sym.kind = EdgeCondition::Kind::kSymmetry;
  sym.side = PlySide::kX0;
  EdgeCondition clamp;
  clamp.kind = EdgeCondition::Kind::kClamp;
  clamp.side = PlySide::kY0;
  const PlyConditions pc = discretise_conditions(grid, {sym, clamp});
  std::vector<PrescribedParameter> params = pc.parameters;
  std::set<std::tuple<Index, int, int>> held;
  for (const PrescribedParameter& p : params) held.insert({p.node, p.d, p.coord});
  for (Index node = 0; node < model.ply(0).n_nodes(); ++node)
    for (int d = 0; d < 4; ++d)
      if (!held.count({node, d, 1})) params.push_back({node, d, 1, 0.0, Ramp::kLinear, -1});
  problem.prescriptions.add(model, 0, params);
  problem.density = {0.0};

  // Approach chosen so that a is close to a_target (2-D: delta ~ P/(pi E*) (2 ln(2D/a) - 1)).
  const double Es = E / (1.0 - nu * nu);
  const double P_target = kPi * a_target * a_target * Es / (4.0 * R);
  const double approach = P_target / (kPi * Es) * (2.0 * std::log(2.0 * D / a_target) - 1.0);
  RigidTool tool{"cylinder", make_cylinder(Vec3(0, 0, D + R), Vec3::UnitY(), R),
                 ToolMotion::ramped(Vec3(0, 0, -approach), Ramp::kLinear, 1.0)};
  ContactOptions o;
  o.normal.stiffness = 2000.0;  // N/mm^3
  o.normal.augmented = true;
  o.normal.tolerance = 1e-5;  // mm: 4 % of the penalty's own penetration p0 / S_n
  o.search_distance = 1.0;
  std::vector<std::pair<Index, BrickFace>> faces;
  for (const FaceRef& f : grid.side_faces(0, PlySide::kY1)) faces.emplace_back(f.element, f.face);
  problem.model.add_interaction(
      std::make_shared<ToolContact>("hertz", model, ContactSurface(model, 0, faces), tool, o));

  StepperSettings s;
  s.control = Control::kLoad;
  s.steps = 1;
  s.statics.residual_tol_rel = 1e-8;  // the thin width ties x and z across it stiffly: round-off ~1e-10
  const VecX x0 = model.reference_positions();
  SteppingState state{x0, VecX::Zero(x0.size()), 0.0};
  struct Last final : StepObserver {
    StepAction on_step(const StepInfo&, const SteppingState&, const VecX&) override { return StepAction::kContinue; }
  } last;
  const SteppingReport rep = make_stepper(problem, s)->run(state, last);
  EXPECT_EQ(rep.status, SteppingReport::Status::kFinished) << rep.message;

  const auto& c = dynamic_cast<const ToolContact&>(problem.model.interaction(0));
  const InteractionContext ctx{1.0, nullptr, nullptr, 0.0};
  const std::vector<ContactPointRecord> rec = c.sample(state.x, ctx);
  double pmax = 0.0;
  for (const ContactPointRecord& r : rec) pmax = std::max(pmax, r.pressure);
  // Least squares p^2 = A - B x^2.
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const ContactPointRecord& r : rec) {
    if (r.pressure <= 0.3 * pmax) continue;
    const double X = r.position.x() * r.position.x(), Y = r.pressure * r.pressure;
    n += 1;
    sx += X;
    sy += Y;
    sxx += X * X;
    sxy += X * Y;
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double A = (sy - slope * sx) / n;
  HertzResult out;
  out.p0 = std::sqrt(A);
  out.a = std::sqrt(A / -slope);
  // Reaction per unit width, doubled for the half model.
  out.load = 2.0 * c.reactions(state.x, ctx).at(0).force.z() / w;
  out.a_h = std::sqrt(4.0 * out.load * R / (kPi * Es));
  out.p0_h = 2.0 * out.load / (kPi * out.a_h);
  out.elements = n1 * n2;
  return out;
}

TEST(Hertz, CylinderOnHalfSpaceConvergesToTheClosedForm) {
  // Measured (h = the element size over the contact zone): h = a/2: a 9.3 %, p0 4.0 %;
  // h = a/4: a 1.0 %, p0 0.20 %; h = a (one element in contact) is too coarse to fit.
  double previous_a = 1e300, previous_p = 1e300;
  for (const int n_fine : {4, 8}) {
    const HertzResult r = hertz(n_fine);
    const double ea = std::abs(r.a - r.a_h) / r.a_h, ep = std::abs(r.p0 - r.p0_h) / r.p0_h;
    std::printf(
        "Hertz, h = a/%d (%d bricks): P = %.5g N/mm, a = %.5g mm (Hertz %.5g, error %.2e), p0 = %.5g MPa (Hertz %.5g, "
        "error %.2e)\n",
        n_fine / 2, r.elements, r.load, r.a, r.a_h, ea, r.p0, r.p0_h, ep);
    EXPECT_LT(ea, 0.5 * previous_a);
    EXPECT_LT(ep, 0.5 * previous_p);
    previous_a = ea;
    previous_p = ep;
  }
  EXPECT_LT(previous_a, 0.02);
  EXPECT_LT(previous_p, 0.01);
}

}  // namespace
}  // namespace sf::forming
