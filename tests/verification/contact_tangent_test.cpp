// The contact tangent against central finite differences of the contact residual
// (forming/contact/contact_kernel.hpp; IPC Toolkit style: every gradient and Hessian
// against finite differences). Each case builds two plies (or a ply and a tool) in a
// perturbed, curved state where every contact point is well inside its regime (clearly
// penetrating, slipping fast or slow against the stick velocity), so central differences
// of step 1e-6 mm see a smooth force, and compares:
//   * d force / dx   with the stiffness the interaction adds (normal, viscous,
//                    Coulomb in slip and in stick, combined; quasi-static rates from a
//                    previous state and dynamic rates from velocities);
//   * d force / dv   with the damping (dynamic runs);
//   * the force      with the gradient of the energy (frictionless: a potential);
// for ply-ply contact (the moving foot point: its terms are most of the tangent) and
// ply-tool contact (analytic sphere; and a test-only shape whose force direction is not
// the gap gradient, as for a meshed tool, so the tangent is unsymmetric).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <set>
#include <vector>

#include "forming/contact/body_contact.hpp"
#include "forming/contact/tool_contact.hpp"
#include "forming/contact/tool_shape.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

constexpr double kFdStep = 1e-6;  // mm (positions O(10)); truncation ~h^2, round-off ~eps/h
// FD stiffness / damping / force against the analytic ones, relative to the largest entry
// (measured 1e-9 .. 1e-7).
constexpr double kFdRel = 2e-6;

struct Share {
  double energy = 0.0;
  VecX force;
  MatX stiffness, damping;
};

Share evaluate(const Interaction& c, Index n, const VecX& x, const InteractionContext& ctx, bool tangent) {
  InteractionSums sums;
  sums.force = VecX::Zero(n);
  linalg::TripletAssembler k(n, n), d(n, n);
  if (tangent) {
    sums.stiffness = &k;
    if (ctx.velocity) sums.damping = &d;
  }
  c.add_to(x, ctx, sums);
  EXPECT_TRUE(sums.ok) << sums.message;
  Share s{sums.energy, sums.force, {}, {}};
  if (tangent) {
    s.stiffness = MatX(k.compress());
    if (ctx.velocity) s.damping = MatX(d.compress());
  }
  return s;
}

struct Errors {
  double stiffness = 0.0, damping = 0.0, energy = 0.0;
  double largest_force = 0.0;
};

// FD of the force in x (stiffness), in v (damping, when ctx has velocities) and of the
// energy (force, when `potential`).
Errors finite_differences(const Interaction& c, Index n, const VecX& x, const InteractionContext& ctx, bool potential) {
  const Share s = evaluate(c, n, x, ctx, true);
  MatX k_fd = MatX::Zero(n, n), d_fd;
  VecX f_fd = VecX::Zero(n);
  if (ctx.velocity) d_fd = MatX::Zero(n, n);
  // Columns the contact touches (its surfaces' dofs), and every 7th other one, which must
  // come out zero.
  for (Index j = 0; j < n; ++j) {
    const bool touched = s.stiffness.col(j).cwiseAbs().maxCoeff() > 0.0 || s.force(j) != 0.0 ||
                         (ctx.velocity && s.damping.col(j).cwiseAbs().maxCoeff() > 0.0);
    if (!touched && j % 7 != 0) continue;
    VecX xp = x, xm = x;
    xp(j) += kFdStep;
    xm(j) -= kFdStep;
    const Share p = evaluate(c, n, xp, ctx, false), m = evaluate(c, n, xm, ctx, false);
    k_fd.col(j) = (p.force - m.force) / (2 * kFdStep);
    f_fd(j) = (p.energy - m.energy) / (2 * kFdStep);
    if (ctx.velocity) {
      VecX vp = *ctx.velocity, vm = *ctx.velocity;
      vp(j) += kFdStep;
      vm(j) -= kFdStep;
      InteractionContext cp = ctx, cm = ctx;
      cp.velocity = &vp;
      cm.velocity = &vm;
      d_fd.col(j) = (evaluate(c, n, x, cp, false).force - evaluate(c, n, x, cm, false).force) / (2 * kFdStep);
    }
  }
  Errors e;
  e.largest_force = max_abs(s.force);
  e.stiffness = max_abs(k_fd - s.stiffness) / max_abs(s.stiffness);
  if (ctx.velocity) e.damping = max_abs(d_fd - s.damping) / max_abs(s.damping);
  if (potential) e.energy = max_abs(f_fd - s.force) / max_abs(s.force);
  return e;
}

// Two plies: a lower one on [0, 10] x [0, 8] (thickness 1, 2 x 2 elements) and an upper
// one overlapping it by 0.05 mm, larger and meshed differently (3 x 3 elements on
// [-0.5, 10.5] x [-0.5, 8.5]) so every lower contact point has a partner; every dof
// perturbed by up to 0.02 mm (curved, non-matching surfaces).
struct TwoPlies {
  Model model;
  VecX x;
};

TwoPlies two_plies(unsigned seed, double upper_z = 0.95) {
  TwoPlies t;
  const auto law = fixtures::neo_hookean(1.0, 1.0);
  t.model.add_ply(fixtures::rectangle_ply(10.0, 8.0, 1.0, 2, 2), law);
  t.model.add_ply(
      PlyMesh(mesh::make_rectangle_mesh(Vec3(-0.5, -0.5, upper_z), Vec3::UnitX(), Vec3::UnitY(), 11.0, 9.0, 3, 3), 1.0,
              30.0),
      law);
  t.x = t.model.reference_positions();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < t.x.size(); ++i) t.x(i) += 0.02 * u(rng);
  return t;
}

std::shared_ptr<BodyContact> ply_contact(const Model& model, const ContactOptions& o) {
  return std::make_shared<BodyContact>("ply-ply", model, ContactSurface::whole_face(model, 0, true),
                                       ContactSurface::whole_face(model, 1, false), o);
}

ContactOptions options(double viscous, double mu, double eps) {
  ContactOptions o;
  o.normal.stiffness = 100.0;
  o.friction.viscous = viscous;
  o.friction.coulomb = mu;
  o.friction.stick_velocity = eps;
  o.friction.engage_gap = 1.0;  // every point engaged
  return o;
}

// Every contact point of the case has a partner and is penetrating.
void expect_all_closed(const SurfaceContact& c, const VecX& x) {
  int open = 0;
  for (const ContactPointRecord& r : c.sample(x, {})) open += !(r.partner && r.gap < -1e-3);
  EXPECT_EQ(open, 0);
}

TEST(ContactTangent, PlyPlyNormalContactIsAPotentialWithAnExactSymmetricTangent) {
  TwoPlies t = two_plies(test::kSeed + 21);
  const auto c = ply_contact(t.model, options(0, 0, 0));
  expect_all_closed(*c, t.x);
  const Errors e = finite_differences(*c, t.model.n_dofs(), t.x, {}, true);
  EXPECT_LT(e.stiffness, kFdRel);
  EXPECT_LT(e.energy, kFdRel);
  const MatX K = evaluate(*c, t.model.n_dofs(), t.x, {}, true).stiffness;
  EXPECT_LT(max_abs(K - K.transpose()), 1e-12 * max_abs(K));
  std::printf("ply-ply normal: FD stiffness %.1e, FD force (energy) %.1e\n", e.stiffness, e.energy);
}

// Quasi-static rates: the previous state is the current one moved back by a slip of the
// lower ply along (1, 0.3) and noise, over dt = 0.1 s.
InteractionContext quasi_static(const TwoPlies& t, VecX& previous, double slip) {
  previous = t.x;
  std::mt19937 rng(test::kSeed + 5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index node = 0; node < t.model.ply(0).n_nodes(); ++node) {
    previous(t.model.dof(0, node, 0, 0)) -= slip;
    previous(t.model.dof(0, node, 0, 1)) -= 0.3 * slip;
  }
  for (Index i = 0; i < previous.size(); ++i) previous(i) += 1e-3 * u(rng);
  return InteractionContext{1.0, nullptr, &previous, 0.9};
}

TEST(ContactTangent, PlyPlyFrictionQuasiStatic) {
  TwoPlies t = two_plies(test::kSeed + 22);
  VecX previous;
  const InteractionContext ctx = quasi_static(t, previous, 0.05);  // slip rate ~0.5 mm/s
  struct Case {
    const char* name;
    ContactOptions o;
  };
  for (const Case& cs : {Case{"viscous", options(0.02, 0, 0)}, Case{"Coulomb slip", options(0, 0.3, 1e-3)},
                         Case{"Coulomb stick", options(0, 0.3, 50.0)}, Case{"combined", options(0.02, 0.3, 0.05)}}) {
    const auto c = ply_contact(t.model, cs.o);
    const Errors e = finite_differences(*c, t.model.n_dofs(), t.x, ctx, false);
    EXPECT_LT(e.stiffness, kFdRel) << cs.name;
    std::printf("ply-ply %s (quasi-static): FD stiffness %.1e\n", cs.name, e.stiffness);
  }
}

// Coulomb regularised by slip distance (contact_law.hpp, stick_slip): sliding (d well
// below the step's slip of ~0.05 mm) and sticking (d well above it), alone and with the
// viscous layer, first from no elastic slip and then after a commit has left one at every
// point (the shift e / dt of the kernel), so both the return map's branches and the state
// are exercised.
TEST(ContactTangent, PlyPlyCoulombBySlipDistance) {
  TwoPlies t = two_plies(test::kSeed + 26);
  VecX previous;
  const InteractionContext ctx = quasi_static(t, previous, 0.05);
  struct Case {
    const char* name;
    double viscous, d;
  };
  for (const Case& cs : {Case{"slip", 0.0, 0.005}, Case{"stick", 0.0, 0.5}, Case{"viscous + slip", 0.02, 0.005},
                         Case{"viscous + stick", 0.02, 0.5}}) {
    ContactOptions o = options(cs.viscous, 0.3, 0);
    o.friction.stick_slip = cs.d;
    const auto c = ply_contact(t.model, o);
    const Errors e0 = finite_differences(*c, t.model.n_dofs(), t.x, ctx, false);
    double largest = 0.0;
    for (const ContactPointRecord& r : c->sample(t.x, ctx)) largest = std::max(largest, r.elastic_slip.norm());
    EXPECT_GT(largest, 0.5 * std::min(cs.d, 0.04)) << cs.name;
    EXPECT_LE(largest, cs.d * (1 + 1e-12)) << cs.name;
    c->commit(t.x, ctx);  // e = s d / max(|s|, d) at every point
    // The next step: the lower ply slides on by 0.02 mm across the first slip.
    VecX next = t.x;
    for (Index node = 0; node < t.model.ply(0).n_nodes(); ++node) {
      next(t.model.dof(0, node, 0, 0)) -= 0.004;
      next(t.model.dof(0, node, 0, 1)) += 0.02;
    }
    const Errors e1 = finite_differences(*c, t.model.n_dofs(), next, InteractionContext{1.1, nullptr, &t.x, 1.0}, false);
    EXPECT_LT(e0.stiffness, kFdRel) << cs.name;
    EXPECT_LT(e1.stiffness, kFdRel) << cs.name;
    std::printf("ply-ply Coulomb by slip distance, %s: FD stiffness %.1e (no elastic slip), %.1e (after a commit)\n",
                cs.name, e0.stiffness, e1.stiffness);
  }
}

TEST(ContactTangent, PlyPlyFrictionDynamic) {
  TwoPlies t = two_plies(test::kSeed + 23);
  VecX v = VecX::Zero(t.x.size());
  std::mt19937 rng(test::kSeed + 6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < v.size(); ++i) v(i) = 0.1 * u(rng);
  for (Index node = 0; node < t.model.ply(1).n_nodes(); ++node) v(t.model.dof(1, node, 0, 0)) += 2.0;
  const InteractionContext ctx{0.5, &v, nullptr, 0.0};
  for (const ContactOptions& o : {options(0.02, 0, 0), options(0, 0.3, 1e-2), options(0, 0.3, 100.0)}) {
    const auto c = ply_contact(t.model, o);
    const Errors e = finite_differences(*c, t.model.n_dofs(), t.x, ctx, false);
    EXPECT_LT(e.stiffness, kFdRel) << o.friction.describe();
    EXPECT_LT(e.damping, kFdRel) << o.friction.describe();
    std::printf("ply-ply %s (dynamic): FD stiffness %.1e, FD damping %.1e\n", o.friction.describe().c_str(),
                e.stiffness, e.damping);
  }
}

// The normal law's tail (contact_law.hpp): the upper ply lifted so that the points
// spread from penetrating through the rounded band to well beyond its open end (only
// the tail acts there); frictionless (a potential: energy, force and a symmetric
// tangent) and with Coulomb friction, which takes the bearing pressure only.
TEST(ContactTangent, PlyPlyNormalLawTailAcrossTheBand) {
  TwoPlies t = two_plies(test::kSeed + 25, 1.01);
  VecX previous;
  const InteractionContext ctx = quasi_static(t, previous, 0.05);
  for (double reach : {0.0, 0.01}) {
    ContactOptions o = options(0, 0, 0);
    o.normal.tail = 2.0;
    o.normal.tail_reach = reach;
    o.band = 0.01;
    const auto c = ply_contact(t.model, o);
    int tie = 0, bearing = 0;
    for (const ContactPointRecord& r : c->sample(t.x, {})) {
      ASSERT_TRUE(r.partner);
      tie += r.gap > 0.5 * o.band;
      bearing += r.gap < 0.5 * o.band;
    }
    EXPECT_GT(tie, 20);  // both regimes well represented
    EXPECT_GT(bearing, 20);
    const Errors e = finite_differences(*c, t.model.n_dofs(), t.x, {}, true);
    EXPECT_LT(e.stiffness, kFdRel) << "reach " << reach;
    EXPECT_LT(e.energy, kFdRel) << "reach " << reach;
    const MatX K = evaluate(*c, t.model.n_dofs(), t.x, {}, true).stiffness;
    EXPECT_LT(max_abs(K - K.transpose()), 1e-12 * max_abs(K));
    o.friction.coulomb = 0.3;
    o.friction.stick_velocity = 0.05;
    const auto f = ply_contact(t.model, o);
    const Errors ef = finite_differences(*f, t.model.n_dofs(), t.x, ctx, false);
    EXPECT_LT(ef.stiffness, kFdRel) << "reach " << reach;
    std::printf("ply-ply tail (reach %g; %d tie, %d bearing points): FD stiffness %.1e, FD force %.1e, with "
                "Coulomb %.1e\n", reach, tie, bearing, e.stiffness, e.energy, ef.stiffness);
  }
}

// The released linear tail (contact_law.hpp, NormalLaw::tail_release: 0.9 x the search
// distance): a search distance of 0.06 mm puts the tie's taper at partings 0.027-0.054 mm,
// inside the spread of the lifted ply's gaps, so points sit in the bearing band, on the
// linear tie, in the taper and beyond it (where they carry nothing before leaving the search).
TEST(ContactTangent, PlyPlyReleasedTailAcrossItsRelease) {
  TwoPlies t = two_plies(test::kSeed + 26, 1.01);
  VecX previous;
  const InteractionContext ctx = quasi_static(t, previous, 0.05);
  ContactOptions o = options(0, 0, 0);
  o.normal.tail = 2.0;
  o.band = 0.01;
  o.search_distance = 0.06;
  const auto c = ply_contact(t.model, o);
  const double release = c->normal_law().tail_release;
  EXPECT_DOUBLE_EQ(release, 0.054);
  int bearing = 0, rising = 0, softening = 0, released = 0;
  for (const ContactPointRecord& r : c->sample(t.x, {})) {
    if (!r.partner) continue;
    const double x = r.gap - 0.5 * o.band;  // the parting beyond the open end
    bearing += x < 0.0;
    rising += x > 0.0 && x < release / 2.0;
    softening += x > release / 2.0 && x < release;
    released += x > release;
  }
  EXPECT_GT(bearing, 10);
  EXPECT_GT(rising, 5);
  EXPECT_GT(softening, 3);
  EXPECT_GE(released, 0);  // (few: from R + band / 2 to the search distance)
  const Errors e = finite_differences(*c, t.model.n_dofs(), t.x, {}, true);
  EXPECT_LT(e.stiffness, kFdRel);
  EXPECT_LT(e.energy, kFdRel);
  const MatX K = evaluate(*c, t.model.n_dofs(), t.x, {}, true).stiffness;
  EXPECT_LT(max_abs(K - K.transpose()), 1e-12 * max_abs(K));
  o.friction.viscous = 0.02;
  o.friction.coulomb = 0.3;
  o.friction.stick_velocity = 0.05;
  const auto f = ply_contact(t.model, o);
  const Errors ef = finite_differences(*f, t.model.n_dofs(), t.x, ctx, false);
  EXPECT_LT(ef.stiffness, kFdRel);
  std::printf("ply-ply released tail (R %g mm; %d bearing, %d linear, %d taper, %d released points): FD "
              "stiffness %.1e, FD force %.1e, with friction %.1e\n",
              release, bearing, rising, softening, released, e.stiffness, e.energy, ef.stiffness);
}

// A ply under a large sphere that overlaps its whole top face.
struct UnderTool {
  Model model;
  VecX x;
};

UnderTool ply_under_tool(unsigned seed) {
  UnderTool t;
  t.model.add_ply(fixtures::rectangle_ply(10.0, 8.0, 1.0, 2, 2), fixtures::neo_hookean(1.0, 1.0));
  t.x = t.model.reference_positions();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index i = 0; i < t.x.size(); ++i) t.x(i) += 0.02 * u(rng);
  return t;
}

// A test-only shape whose force direction is not its gap gradient (as for a meshed
// tool): g = (x - p) . a + 0.001 |x - p|^2, n = normalize(b + B (x - p)).
class SkewShape final : public ToolShape {
 public:
  std::string kind() const override { return "skew"; }
  bool symmetric() const override { return false; }
  ToolPoint evaluate(const Vec3& x) const override {
    const Vec3 d = x - p_;
    ToolPoint t;
    t.gap = d.dot(a_) + 0.001 * d.squaredNorm();
    t.gap_gradient = a_ + 0.002 * d;
    const Vec3 m = b_ + B_ * d;
    t.normal = m.normalized();
    t.normal_gradient = (Mat3::Identity() - t.normal * t.normal.transpose()) * B_ / m.norm();
    return t;
  }
  ToolTessellation tessellate(const Vec3&, const Vec3&) const override { return {}; }

 private:
  Vec3 p_{5, 4, 0.7}, a_{Vec3(0.01, 0.005, -1).normalized()}, b_{Vec3(-0.2, 0.1, -1).normalized()};
  Mat3 B_ = (Mat3() << 0.01, 0.02, 0, -0.01, 0.03, 0.01, 0.02, 0, -0.02).finished();
};

// The solver's path: contact scattered into the kept pattern of the free unknowns
// (Model::assemble_into, the pattern growing when a pair falls outside it) against the
// triplet assembly of the same model (Model::assemble_reference), at two states whose
// contact pairs differ (the upper ply slid 2 mm: the lower ply's points find other
// master faces, some none), with one pattern assembler across both as in a Newton
// solve; and the contact tangent at the second state against central differences.
TEST(ContactTangent, PatternAssembledTangentEqualsTripletsWhenPairsChange) {
  TwoPlies t = two_plies(test::kSeed + 25);
  VecX previous;
  const InteractionContext ctx = quasi_static(t, previous, 0.05);
  const auto c = ply_contact(t.model, options(0.02, 0.3, 0.05));
  t.model.add_interaction(c);
  const Index n = t.model.n_dofs();
  linalg::PatternAssembler pattern = t.model.make_pattern(std::vector<bool>(static_cast<std::size_t>(n), true), false);
  const auto pairs = [&](const VecX& x) {
    std::set<std::vector<Index>> out;
    c->pattern_blocks(x, ctx, [&](const std::vector<Index>&, const std::vector<Index>& cols) { out.insert(cols); });
    return out;
  };
  VecX slid = t.x;
  for (Index node = 0; node < t.model.ply(1).n_nodes(); ++node) slid(t.model.dof(1, node, 0, 0)) += 2.0;
  const auto pairs_before = pairs(t.x), pairs_after = pairs(slid);
  EXPECT_NE(pairs_before, pairs_after);
  int state = 0;
  for (const VecX* x : {&t.x, &slid, &t.x}) {
    const Assembly a = t.model.assemble_into(*x, ctx, &pattern);
    const Assembly r = t.model.assemble_reference(*x, ctx, true);
    ASSERT_TRUE(a.ok && r.ok) << a.message << r.message;
    const MatX K(pattern.matrix()), R(r.tangent);
    const double rel = max_abs(K - R) / max_abs(R);
    EXPECT_LT(rel, 1e-13) << "state " << state;
    EXPECT_LT(max_abs(a.force - r.force), 1e-13 * max_abs(r.force)) << "state " << state;
    std::printf("state %d: %zu contact pairs, pattern generation %d, |K_pattern - K_triplets| / |K| %.1e\n", state,
                (x == &slid ? pairs_after : pairs_before).size(), pattern.generation(), rel);
    ++state;
  }
  const Errors e = finite_differences(*c, n, slid, ctx, false);
  EXPECT_LT(e.stiffness, kFdRel);
  std::printf("slid state: FD stiffness %.1e\n", e.stiffness);
}

TEST(ContactTangent, PlyToolNormalAndFriction) {
  UnderTool t = ply_under_tool(test::kSeed + 24);
  const RigidTool sphere{"punch", make_sphere(Vec3(5, 4, 1 + 200 - 0.3), 200.0),
                         ToolMotion::ramped(Vec3(0.5, 0.2, -0.1), Ramp::kSmooth, 2.0)};
  const RigidTool skew{"skew", std::make_shared<SkewShape>(), ToolMotion::constant_velocity(Vec3(0.3, 0, 0))};
  VecX previous = t.x;
  for (Index i = 0; i < previous.size(); i += 3) previous(i) -= 0.01;
  VecX v = VecX::Zero(t.x.size());
  for (Index i = 0; i < v.size(); i += 3) v(i) = -0.7;
  const InteractionContext none{1.0, nullptr, nullptr, 0.0};
  const InteractionContext qs{1.0, nullptr, &previous, 0.95};
  const InteractionContext dyn{1.0, &v, nullptr, 0.0};
  for (const RigidTool& tool : {sphere, skew}) {
    const auto normal = std::make_shared<ToolContact>("n", t.model, ContactSurface::whole_face(t.model, 0, true), tool,
                                                      options(0, 0, 0));
    expect_all_closed(*normal, t.x);
    const Errors en = finite_differences(*normal, t.model.n_dofs(), t.x, none, tool.shape->symmetric());
    EXPECT_LT(en.stiffness, kFdRel) << tool.name;
    if (tool.shape->symmetric()) {
      EXPECT_LT(en.energy, kFdRel);
    }
    std::printf("ply-tool %s normal: FD stiffness %.1e, FD force %.1e\n", tool.name.c_str(), en.stiffness, en.energy);
    for (const ContactOptions& o :
         {options(0.02, 0, 0), options(0, 0.3, 1e-3), options(0, 0.3, 100.0), options(0.02, 0.3, 0.2)}) {
      const auto c = std::make_shared<ToolContact>("f", t.model, ContactSurface::whole_face(t.model, 0, true), tool, o);
      const Errors eq = finite_differences(*c, t.model.n_dofs(), t.x, qs, false);
      const Errors ed = finite_differences(*c, t.model.n_dofs(), t.x, dyn, false);
      EXPECT_LT(eq.stiffness, kFdRel) << tool.name << " " << o.friction.describe();
      EXPECT_LT(ed.stiffness, kFdRel) << tool.name << " " << o.friction.describe();
      EXPECT_LT(ed.damping, kFdRel) << tool.name << " " << o.friction.describe();
      std::printf("ply-tool %s %s: quasi-static FD stiffness %.1e; dynamic %.1e, damping %.1e\n", tool.name.c_str(),
                  o.friction.describe().c_str(), eq.stiffness, ed.stiffness, ed.damping);
    }
    for (double d : {1e-4, 0.1}) {  // slip (the step slides 0.01 mm), stick
      ContactOptions o = options(0.02, 0.3, 0);
      o.friction.stick_slip = d;
      const auto c = std::make_shared<ToolContact>("f", t.model, ContactSurface::whole_face(t.model, 0, true), tool, o);
      c->commit(t.x, qs);  // the next step from an elastic slip: the ply moved on by 0.005 mm along y
      VecX next = t.x;
      for (Index i = 1; i < next.size(); i += 3) next(i) += 0.005;
      const Errors eq =
          finite_differences(*c, t.model.n_dofs(), next, InteractionContext{1.05, nullptr, &t.x, 1.0}, false);
      EXPECT_LT(eq.stiffness, kFdRel) << tool.name << " " << o.friction.describe();
      std::printf("ply-tool %s %s: quasi-static FD stiffness %.1e\n", tool.name.c_str(), o.friction.describe().c_str(),
                  eq.stiffness);
    }
  }
}

}  // namespace
}  // namespace sf::forming
