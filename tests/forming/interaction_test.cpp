// Interactions between bodies (forming/model/interaction.hpp) summed into the model's
// assembly, exercised with node springs (forming/model/node_spring.hpp) and, for the
// velocity path of the dynamic solver, a test-only damping interaction:
//
//  * finite differences: at a perturbed state of two blocks joined by springs, the
//    springs' share of the assembly (with minus without springs) has a force equal to
//    the central difference of its energy and a stiffness equal to the central
//    difference of its force;
//  * closed form: two blocks in series joined by four springs, pulled at the far end.
//    With the neo-Hookean law at lambda = 0 uniaxial stress has no lateral contraction,
//    F = diag(l, 1, 1), nominal stress P = mu (l - 1/l); the blocks (one element across,
//    so the four value nodes of an end face share its traction equally) stretch
//    homogeneously and each spring carries P W H / 4. For a chosen l the far-end
//    displacement is u = 2 L (l - 1) + P W H / (4 k); the static solve must return
//    F = diag(l, 1, 1) at every Gauss point of both blocks, that tension in every
//    spring, that reaction at the far end and the springs' energy in the assembly;
//  * an inadmissible state (a spring of zero length) is an assembly failure, not a throw;
//  * velocities: a free ply with mass-proportional damping f = c M v started in uniform
//    translation decays as v0 exp(-c t) (elements see a rigid motion: no internal
//    force); the solver must take one Newton iteration per time step (the damping enters
//    the effective tangent) and the error must fall at second order in dt.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "common/core/error.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/model/model.hpp"
#include "forming/model/node_spring.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/solve/dynamic_solver.hpp"
#include "forming/solve/static_solver.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

// ---- Named tolerances -------------------------------------------------------------
// Central-difference step in positions (mm, sizes O(1)); truncation ~ h^2, round-off
// ~ eps / h relative.
constexpr double kFdStep = 1e-6;
// FD force / stiffness of the springs against the analytic ones, relative to the
// largest entry (measured ~1e-10).
constexpr double kFdRel = 1e-7;
// The series system's closed form: F, spring tension, reaction and energy, relative to
// their size; Newton stops at 1e-12 of the force scale (measured ~1e-13).
constexpr double kClosedFormRel = 1e-9;
// Damped translation against v0 exp(-c t) with c dt = 0.1 (trapezoidal rule: relative
// error (c dt)^2 c t / 12 ~ 8e-4 at c t = 1) and the order from halving dt (4 for
// second order).
constexpr double kDampedDecayRel = 2e-3;
constexpr double kOrderRatioLow = 3.8, kOrderRatioHigh = 4.2;

// ---- The series system ------------------------------------------------------------

constexpr double kMu = 1.0;                     // MPa, lambda = 0
constexpr double kL = 2.0, kW = 1.0, kH = 0.5;  // block size, mm
constexpr double kGap = 0.5;                    // between the blocks, mm (spring rest length)
constexpr double kSpring = 0.25;                // N/mm per spring
constexpr int kAlong = 2;                       // elements along x per block

double nominal_stress(double l) { return kMu * (l - 1.0 / l); }

struct Series {
  Model model;
  std::vector<std::shared_ptr<NodeSpring>> springs;
  std::vector<BodyNode> far_end;  // value nodes of block B's free end
};

// Block A on [0, L], block B on [L + gap, 2 L + gap] (x), both [0, W] x [0, H]; four
// springs join A's end x = L to B's end x = L + gap, node to node.
Series series(bool with_springs) {
  Series s;
  const auto law = fixtures::neo_hookean(kMu, 0.0);
  s.model.add_ply(fixtures::rectangle_ply(kL, kW, kH, kAlong, 1), law);
  s.model.add_ply(
      PlyMesh(mesh::make_rectangle_mesh(Vec3(kL + kGap, 0.0, 0.0), Vec3::UnitX(), Vec3::UnitY(), kL, kW, kAlong, 1), kH,
              0.0),
      law);
  const PlyGrid grid{kAlong, 1};
  for (int j = 0; j <= 1; ++j)
    for (int layer = 0; layer < 2; ++layer) {
      const Index end_a = grid.surface_node(kAlong, j) + layer * grid.n_surface_nodes();
      const Index end_b = grid.surface_node(0, j) + layer * grid.n_surface_nodes();
      const Index far_b = grid.surface_node(kAlong, j) + layer * grid.n_surface_nodes();
      s.far_end.push_back({1, far_b});
      if (!with_springs) continue;
      s.springs.push_back(std::make_shared<NodeSpring>(s.model, BodyNode{0, end_a}, BodyNode{1, end_b}, kSpring, kGap));
      s.model.add_interaction(s.springs.back());
    }
  return s;
}

// Block A: symmetry planes x0, y0 and bottom; block B: y0 and bottom, its far end x1
// moved by u along x. The along-edge derivative of x on the spring ends is held at its
// reference value (as a displacement condition does on a driven edge), which the
// homogeneous solution has; only the value nodes then carry the springs' forces.
Prescriptions series_prescriptions(const Model& model, double u) {
  using Kind = EdgeCondition::Kind;
  const PlyGrid grid{kAlong, 1};
  const std::vector<EdgeCondition> a = {{Kind::kSymmetry, PlySide::kX0, {}, Ramp::kLinear},
                                        {Kind::kSymmetry, PlySide::kY0, {}, Ramp::kLinear},
                                        {Kind::kSymmetry, PlySide::kBottom, {}, Ramp::kLinear}};
  std::vector<EdgeCondition> b = {a[1], a[2]};
  b.push_back({Kind::kDisplacement, PlySide::kX1, {u, std::nullopt, std::nullopt}, Ramp::kLinear});
  Prescriptions out;
  for (int body = 0; body < 2; ++body) {
    PlyConditions c = discretise_conditions(grid, body == 0 ? a : b);
    EXPECT_TRUE(c.conflicts.empty());
    // d/ds2 of x on the spring end of y = W (y = 0 is held by the symmetry plane y0).
    const Index end = grid.surface_node(body == 0 ? kAlong : 0, 1);
    for (int layer = 0; layer < 2; ++layer)
      c.parameters.push_back({end + layer * grid.n_surface_nodes(), mesh::kD2, 0, 0.0, Ramp::kLinear, -1});
    out.add(model, body, c.parameters);
  }
  return out;
}

TEST(Interaction, SpringForceAndStiffnessMatchFiniteDifferences) {
  const Series with = series(true);
  const Series without = series(false);
  const Model& model = with.model;
  std::mt19937 rng(test::kSeed + 7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX x = model.reference_positions();
  for (Index i = 0; i < x.size(); ++i) x(i) += 0.05 * u(rng);

  // The springs' share of energy, force and stiffness at x.
  struct Share {
    double energy;
    VecX force;
    MatX stiffness;
  };
  const auto share = [&](const VecX& xs, bool tangent) {
    const Assembly a = model.assemble(xs, tangent), b = without.model.assemble(xs, tangent);
    EXPECT_TRUE(a.ok && b.ok) << a.message << b.message;
    EXPECT_DOUBLE_EQ(a.strain_energy, b.strain_energy);
    return Share{a.energy - b.energy, a.force - b.force, tangent ? MatX(MatX(a.tangent) - MatX(b.tangent)) : MatX()};
  };
  const Share s = share(x, true);
  ASSERT_GT(max_abs(s.force), 0.0);
  MatX k_fd(x.size(), x.size());
  VecX f_fd(x.size());
  for (Index j = 0; j < x.size(); ++j) {
    VecX xp = x, xm = x;
    xp(j) += kFdStep;
    xm(j) -= kFdStep;
    const Share p = share(xp, false), m = share(xm, false);
    k_fd.col(j) = (p.force - m.force) / (2.0 * kFdStep);
    f_fd(j) = (p.energy - m.energy) / (2.0 * kFdStep);
  }
  const double e_k = max_abs(k_fd - s.stiffness) / max_abs(s.stiffness);
  const double e_f = max_abs(f_fd - s.force) / max_abs(s.force);
  EXPECT_LT(e_k, kFdRel);
  EXPECT_LT(e_f, kFdRel);
  EXPECT_LT(max_abs(s.stiffness - s.stiffness.transpose()), 1e-14 * max_abs(s.stiffness));
  // Newton's third law: the springs' forces sum to zero in every direction.
  Vec3 total = Vec3::Zero();
  for (Index i = 0; i < x.size(); i += 3) total += s.force.segment<3>(i);
  EXPECT_LT(total.norm(), 1e-14 * max_abs(s.force));
  std::printf("node springs: FD stiffness %.1e, FD force %.1e (relative)\n", e_k, e_f);
}

TEST(Interaction, SpringsInSeriesWithTwoBlocksGiveTheClosedForm) {
  const double l = 1.2;
  const double force = nominal_stress(l) * kW * kH;   // N through every section
  const double extension = force / (4.0 * kSpring);   // mm per spring
  const double u = 2.0 * kL * (l - 1.0) + extension;  // mm at the far end
  Series s = series(true);
  const Prescriptions prescribed = series_prescriptions(s.model, u);
  StaticOptions options;
  options.residual_tol_rel = 1e-12;
  options.initial_increment = 0.25;
  const StaticResult r = solve_static(s.model, s.model.reference_positions(), prescribed.at(1.0), VecX(), options);
  ASSERT_TRUE(r.report.ok()) << r.report.brief();

  const Mat3 F_exact = Vec3(l, 1.0, 1.0).asDiagonal();
  double e_F = 0.0;
  for (int body = 0; body < 2; ++body)
    for (const Mat3& F : s.model.deformation_gradients(body, r.positions)) e_F = std::max(e_F, max_abs(F - F_exact));
  double e_t = 0.0;
  for (const auto& spring : s.springs)
    e_t = std::max(e_t, std::abs(spring->tension(r.positions) - force / 4.0) / (force / 4.0));
  double reaction = 0.0;
  for (const BodyNode& n : s.far_end) reaction += r.reactions(s.model.dof(n.body, n.node, 0, 0));
  const Assembly a = s.model.assemble(r.positions, false);
  const double spring_energy = 4.0 * 0.5 * kSpring * extension * extension;
  const double e_energy = std::abs((a.energy - a.strain_energy) - spring_energy) / spring_energy;

  EXPECT_LT(e_F / l, kClosedFormRel);
  EXPECT_LT(e_t, kClosedFormRel);
  EXPECT_NEAR(reaction / force, 1.0, kClosedFormRel) << "reaction " << reaction << " N, force " << force << " N";
  EXPECT_LT(e_energy, kClosedFormRel);
  std::printf(
      "springs in series at stretch %.2f: u = %.6f mm, |F - diag(l, 1, 1)| = %.1e, spring tension %.1e, "
      "reaction %.10f N (P W H = %.10f N), spring energy %.1e (relative errors); %s\n",
      l, u, e_F, e_t, reaction, force, e_energy, r.report.brief().c_str());
}

TEST(Interaction, ZeroLengthSpringIsAnInadmissibleState) {
  Series s = series(false);
  const PlyGrid grid{kAlong, 1};
  const BodyNode end_a{0, grid.surface_node(kAlong, 0)}, end_b{1, grid.surface_node(0, 0)};
  s.model.add_interaction(std::make_shared<NodeSpring>(s.model, end_a, end_b, 1.0, kGap));
  // Block B moved rigidly back by the gap: its end node lands on block A's.
  VecX x = s.model.reference_positions();
  for (Index n = 0; n < s.model.ply(1).n_nodes(); ++n) x(s.model.dof(1, n, 0, 0)) -= kGap;
  const Assembly r = s.model.assemble(x, true);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("zero length"), std::string::npos) << r.message;
  EXPECT_THROW(NodeSpring(s.model, end_a, BodyNode{2, 0}, 1.0, 0.0), InputError);
  EXPECT_THROW(NodeSpring(s.model, end_a, end_b, -1.0, 0.0), InputError);
  EXPECT_THROW(s.model.add_interaction(nullptr), InputError);
}

// ---- Velocities -------------------------------------------------------------------

// Mass-proportional damping f = c M v, D = c M (N s/mm): a test-only interaction whose
// force needs the velocities the dynamic solver hands to interactions.
class MassDamping final : public Interaction {
 public:
  MassDamping(linalg::SparseMatrix mass, double c) : mass_(std::move(mass)), c_(c) {}
  std::string name() const override { return "mass-proportional damping"; }
  bool needs_velocity() const override { return true; }
  void add_to(const Eigen::Ref<const VecX>&, const InteractionContext& context, InteractionSums& sums) const override {
    if (!context.velocity) return;  // quasi-static: no force
    sums.force += c_ * (mass_ * *context.velocity);
    if (!sums.damping) return;
    for (int k = 0; k < mass_.outerSize(); ++k)
      for (linalg::SparseMatrix::InnerIterator it(mass_, k); it; ++it)
        sums.damping->add(it.row(), it.col(), c_ * it.value());
  }

 private:
  linalg::SparseMatrix mass_;
  double c_;
};

struct Decay {
  double error = 0.0;  // max relative error of displacement and velocity at end_time
  int steps = 0, iterations = 0;
};

Decay damped_translation(double dt) {
  const double c = 10.0, v0 = 100.0, end = 0.1;  // 1/s, mm/s, s: c end = 1
  Model model = fixtures::one_ply_model(fixtures::rectangle_ply(2.0, 1.0, 0.2, 2, 1),
                                        std::make_shared<NeoHookean>(NeoHookeanParams::from_young_poisson(1.0, 0.3)));
  const linalg::SparseMatrix mass = mass_matrix(model, {1e-6});  // dense enough that inertia dwarfs round-off
  model.add_interaction(std::make_shared<MassDamping>(mass, c));
  const VecX X = model.reference_positions();
  VecX v = VecX::Zero(X.size());
  for (Index n = 0; n < model.ply(0).n_nodes(); ++n) v(model.dof(0, n, 0, 0)) = v0;
  DynamicOptions o;
  o.end_time = end;
  o.initial_dt = dt;
  o.rho_inf = 1.0;
  o.residual_tol_rel = 1e-8;
  const DynamicResult r = solve_dynamic(model, mass, X, v, {}, {}, o);
  EXPECT_TRUE(r.report.ok()) << r.report.brief();
  const double u_exact = v0 * (1.0 - std::exp(-c * end)) / c, v_exact = v0 * std::exp(-c * end);
  Decay d;
  for (Index n = 0; n < model.ply(0).n_nodes(); ++n) {
    const Index dof = model.dof(0, n, 0, 0);
    d.error = std::max({d.error, std::abs(r.positions(dof) - X(dof) - u_exact) / u_exact,
                        std::abs(r.velocities(dof) - v_exact) / v_exact});
  }
  d.steps = r.report.n_converged_steps;
  d.iterations = r.report.total_iterations;
  return d;
}

TEST(Interaction, VelocityDependentInteractionInDynamicsDecaysExponentially) {
  const Decay coarse = damped_translation(0.01), fine = damped_translation(0.005);
  EXPECT_LT(coarse.error, kDampedDecayRel);
  const double ratio = coarse.error / fine.error;
  EXPECT_GT(ratio, kOrderRatioLow);
  EXPECT_LT(ratio, kOrderRatioHigh);
  // A linear system with the exact effective tangent converges in one Newton solve.
  EXPECT_EQ(coarse.iterations, coarse.steps);
  EXPECT_EQ(fine.iterations, fine.steps);
  std::printf(
      "damped translation c t = 1: error %.2e (dt = 0.01 s), %.2e (dt / 2), ratio %.3f; %d Newton "
      "iterations in %d steps\n",
      coarse.error, fine.error, ratio, coarse.iterations, coarse.steps);
}

}  // namespace
}  // namespace sf::forming
