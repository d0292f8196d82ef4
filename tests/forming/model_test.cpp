// The model's fast assembly (forming/model/model.hpp assemble_into, common/linalg/
// pattern_assembler.hpp): equal to the straightforward triplet assembly it replaced
// (assemble_reference) on plies with graded elements and with an
// interaction whose entries fall outside the elements' pattern; the free-unknown
// lower-triangle layout equal to the reference's K_ff; the direction product K d; and
// the threaded element loop equal to the serial one bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/mesh/surface_mesh.hpp"
#include "forming/model/model.hpp"
#include "forming/model/node_spring.hpp"
#include "forming/model/solve_profile.hpp"
#include "forming/solve/static_solver.hpp"
#include "forming/solve/tangent_solver.hpp"
#include "tests/common/tolerances.hpp"
#include "tests/forming/fixtures.hpp"

namespace sf::forming {
namespace {

using fixtures::max_abs;

// Sums in another order (colours, pattern positions): equal up to round-off of sums of
// ~100 products of O(|K|) terms.
constexpr double kSumOrderRel = 1e-12;

std::shared_ptr<const Material> ti_model_material(const Vec3& a0) {
  return std::make_shared<TransverselyIsotropic>(fixtures::ti_compressible(1.0, 3.0, 50.0, 4.0), a0);
}

// Two plies (graded rectangle, 0 and 30 degrees) joined by node springs between them
// (entries outside either ply's pattern), and a third, neo-Hookean ply. (A disk ply with
// collapsed elements is not used: its bricks have a non-positive reference Jacobian at
// a Gauss point in both the reference and the fast path; plies in forming are not disks
// yet.)
Model test_model() {
  Model model;
  model.add_ply(
      fixtures::rectangle_ply(40.0, 30.0, 1.0, 4, 3, 0.0, PlyPlacement::kBottom, {0.0, 5.0, 20.0, 30.0, 40.0}),
      ti_model_material(fibre_from_layup_angle(0.0)));
  PlyMesh upper(mesh::make_rectangle_mesh(Vec3(0.0, 0.0, 1.5), Vec3::UnitX(), Vec3::UnitY(), 40.0, 30.0, 3, 3), 1.0,
                30.0);
  model.add_ply(std::move(upper), ti_model_material(fibre_from_layup_angle(30.0)));
  model.add_ply(
      PlyMesh(mesh::make_rectangle_mesh(Vec3(0.0, 0.0, 4.0), Vec3::UnitX(), Vec3::UnitY(), 20.0, 10.0, 2, 2), 0.5, 0.0),
      fixtures::neo_hookean(1.0, 4.0));
  for (Index s : {0, 5, 11})
    model.add_interaction(std::make_shared<NodeSpring>(model, BodyNode{0, model.ply(0).node(s, 1)},
                                                       BodyNode{1, model.ply(1).node(s, 0)}, 3.0, 0.5));
  return model;
}

// The reference positions moved smoothly and a little at random (every element stays
// admissible).
VecX deformed(const Model& model, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX x = model.reference_positions();
  for (Index d = 0; d < x.size(); ++d) x(d) += 0.01 * u(rng) + 0.002 * x(d);
  return x;
}

TEST(FormingModel, PatternAssemblyEqualsTripletAssembly) {
  const Model model = test_model();
  const VecX x = deformed(model, test::kSeed);
  const Assembly fast = model.assemble(x, true);
  const Assembly ref = model.assemble_reference(x, InteractionContext{}, true);
  ASSERT_TRUE(fast.ok && ref.ok) << fast.message << ref.message;
  const double scale = max_abs(MatX(ref.tangent));
  EXPECT_LT(max_abs(MatX(fast.tangent) - MatX(ref.tangent)), kSumOrderRel * scale);
  EXPECT_LT(max_abs(fast.force - ref.force), kSumOrderRel * max_abs(ref.force));
  EXPECT_NEAR(fast.energy, ref.energy, kSumOrderRel * std::abs(ref.energy));
  // The same pattern: every stored entry of the reference is stored by the fast path.
  EXPECT_EQ(fast.tangent.nonZeros(), ref.tangent.nonZeros());
}

TEST(FormingModel, FreeUnknownLowerLayoutEqualsReferenceRestriction) {
  const Model model = test_model();
  const VecX x = deformed(model, test::kSeed + 1);
  std::vector<bool> is_free(static_cast<std::size_t>(model.n_dofs()), true);
  for (Index d = 0; d < model.n_dofs(); d += 7) is_free[static_cast<std::size_t>(d)] = false;
  linalg::PatternAssembler lower = model.make_pattern(is_free, true);
  linalg::PatternAssembler full = model.make_pattern(is_free, false);
  VecX dir = VecX::Zero(model.n_dofs());
  for (Index d = 0; d < model.n_dofs(); d += 7) dir(d) = 0.01 * std::sin(double(d));
  const Assembly a = model.assemble_into(x, InteractionContext{}, &lower, &dir);
  model.assemble_into(x, InteractionContext{}, &full);
  const Assembly ref = model.assemble_reference(x, InteractionContext{}, true);
  ASSERT_TRUE(a.ok);
  const FreeDofs free(is_free);
  const MatX kff = MatX(free.select.transpose() * ref.tangent * free.select);
  const double scale = max_abs(kff);
  const MatX l = MatX(lower.matrix());
  EXPECT_LT(max_abs(MatX(kff.triangularView<Eigen::Lower>()) - l), kSumOrderRel * scale);
  EXPECT_TRUE(l.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().isZero(0.0));
  EXPECT_LT(max_abs(MatX(full.matrix()) - kff), kSumOrderRel * scale);
  // K d over all dofs (the predictor's K_fp dx_p).
  const VecX kd = ref.tangent * dir;
  EXPECT_LT(max_abs(a.tangent_times - kd), kSumOrderRel * scale);
  // A second assembly into the same (grown) pattern gives the same values.
  const linalg::SparseMatrix first = lower.matrix();
  const int generation = lower.generation();
  model.assemble_into(x, InteractionContext{}, &lower);
  EXPECT_EQ(lower.generation(), generation);
  EXPECT_EQ(MatX(lower.matrix()), MatX(first));
}

TEST(FormingModel, ThreadedAssemblyEqualsSerialBitForBit) {
  Model model;
  for (int k = 0; k < 2; ++k)
    model.add_ply(fixtures::rectangle_ply(60.0, 40.0, 0.5, 12, 8, 45.0 * k),
                  ti_model_material(fibre_from_layup_angle(45.0 * k)));
  const VecX x = deformed(model, test::kSeed + 2);
  std::vector<bool> is_free(static_cast<std::size_t>(model.n_dofs()), true);
  VecX dir = VecX::Zero(model.n_dofs());
  for (Index d = 0; d < 96; ++d) {
    is_free[static_cast<std::size_t>(d)] = false;
    dir(d) = 0.1;
  }
  model.set_threads(1);
  linalg::PatternAssembler serial = model.make_pattern(is_free, true);
  const Assembly a1 = model.assemble_into(x, InteractionContext{}, &serial, &dir);
  for (int threads : {2, 3}) {
    model.set_threads(threads);
    linalg::PatternAssembler threaded = model.make_pattern(is_free, true);
    const Assembly an = model.assemble_into(x, InteractionContext{}, &threaded, &dir);
    ASSERT_TRUE(an.ok);
    EXPECT_EQ(an.force, a1.force) << threads << " threads";
    EXPECT_EQ(an.energy, a1.energy) << threads << " threads";
    EXPECT_EQ(an.tangent_times, a1.tangent_times) << threads << " threads";
    ASSERT_EQ(threaded.matrix().nonZeros(), serial.matrix().nonZeros());
    EXPECT_TRUE(std::equal(serial.matrix().valuePtr(), serial.matrix().valuePtr() + serial.matrix().nonZeros(),
                           threaded.matrix().valuePtr()))
        << threads << " threads";
  }
}

TEST(FormingModel, InvertedElementIsReportedByTheFastAssembly) {
  Model model;
  model.add_ply(fixtures::rectangle_ply(10.0, 10.0, 1.0, 2, 2), fixtures::neo_hookean(1.0, 4.0));
  VecX x = model.reference_positions();
  for (Index p = 0; p < x.size() / 3; ++p) x(3 * p + 2) *= -1.0;  // mirrored: det F < 0
  linalg::PatternAssembler pattern = model.make_pattern(std::vector<bool>(x.size(), true), true);
  const Assembly a = model.assemble_into(x, InteractionContext{}, &pattern);
  EXPECT_FALSE(a.ok);
  EXPECT_NE(a.message.find("inverted"), std::string::npos) << a.message;
  EXPECT_TRUE(std::isinf(a.energy));
}

// A real ply tangent shifted by a fraction of its mean diagonal, so that many
// eigenvalues are negative, stored as its lower triangle.
struct ShiftedPlyTangent {
  Model model;
  std::vector<bool> is_free;
  linalg::PatternAssembler pattern;
  double mean = 0.0;
  ShiftedPlyTangent() : model(make_model()), is_free(free_dofs(model)), pattern(model.make_pattern(is_free, true)) {
    EXPECT_TRUE(model.assemble_into(model.reference_positions(), InteractionContext{}, &pattern).ok);
    linalg::SparseMatrix& k = pattern.matrix();
    for (int c = 0; c < k.outerSize(); ++c) mean += k.coeff(c, c);
    mean /= k.outerSize();
  }
  void shift(double s) {
    linalg::SparseMatrix& k = pattern.matrix();
    for (int c = 0; c < k.outerSize(); ++c) k.coeffRef(c, c) -= s * mean;
  }
  static Model make_model() {
    Model m;
    m.add_ply(fixtures::rectangle_ply(20.0, 20.0, 1.0, 4, 4, 30.0), ti_model_material(fibre_from_layup_angle(30.0)));
    return m;
  }
  static std::vector<bool> free_dofs(const Model& m) {
    std::vector<bool> f(static_cast<std::size_t>(m.n_dofs()), true);
    for (Index d = 0; d < 48; ++d) f[static_cast<std::size_t>(d)] = false;  // a clamped corner node pair
    return f;
  }
};

double lower_residual(const linalg::SparseMatrix& lower, const VecX& x, const VecX& b) {
  const linalg::SparseMatrix full = lower.selfadjointView<Eigen::Lower>();
  return (full * x - b).norm() / b.norm();
}

// The symmetric-indefinite path: Cholesky breaks down, the indefinite solver (MUMPS's
// LDL^T with pivoting; UMFPACK's LU on the expanded matrix without MUMPS) takes over and
// its solution passes the residual check.
TEST(FormingTangentSolver, IndefiniteTangentIsSolvedByTheFallback) {
  ShiftedPlyTangent t;
  TangentSolver solver(linalg::SolverKind::kAuto, false);
  ASSERT_TRUE(solver.lower());
  t.shift(0.37);
  const linalg::SparseMatrix& k = t.pattern.matrix();
  const linalg::SolveReport& r = solver.factorize(k);
  ASSERT_TRUE(r.ok()) << r.brief();
  EXPECT_EQ(solver.n_indefinite(), 1);
  const bool mumps = linalg::solver_available(linalg::SolverKind::kMumpsLdlt);
  EXPECT_EQ(r.used, mumps                                                    ? linalg::SolverKind::kMumpsLdlt
                    : linalg::solver_available(linalg::SolverKind::kUmfpack) ? linalg::SolverKind::kUmfpack
                                                                             : linalg::SolverKind::kCholmodLdlt);
  if (mumps) {
    EXPECT_GT(r.negative_pivots, 0);
  }
  const VecX b = VecX::LinSpaced(k.rows(), -1.0, 2.0);
  const VecX sol = solver.solve(b);
  EXPECT_LT(lower_residual(k, sol, b), TangentSolver::kResidualTolerance);
  EXPECT_EQ(solver.n_residual_fallbacks(), 0);
  EXPECT_EQ(solver.active()->kind(), r.used);
  // Definite again: the next factorisations stay with the fallback for a while, still right.
  t.shift(-0.37);
  ASSERT_TRUE(solver.factorize(k).ok());
  EXPECT_LT(lower_residual(k, solver.solve(b), b), 1e-8);
}

// The residual check's way out: a solution of the indefinite solver that stays above the
// tolerance after refinement is redone by the LU (here forced by a tolerance of 0, which
// no solution meets), and that one is returned.
TEST(FormingTangentSolver, IndefiniteSolutionFailingTheResidualCheckGoesToTheLu) {
  if (!linalg::solver_available(linalg::SolverKind::kMumpsLdlt)) GTEST_SKIP() << "this build has no MUMPS";
  ShiftedPlyTangent t;
  t.shift(0.37);
  const linalg::SparseMatrix& k = t.pattern.matrix();
  const VecX b = VecX::LinSpaced(k.rows(), -1.0, 2.0);
  solve_profile().reset();
  TangentSolver strict(linalg::SolverKind::kAuto, false);
  strict.set_residual_tolerance(0.0);
  ASSERT_TRUE(strict.factorize(k).ok());
  EXPECT_EQ(strict.active()->kind(), linalg::SolverKind::kMumpsLdlt);
  const VecX x = strict.solve(b);
  EXPECT_EQ(strict.n_residual_fallbacks(), 1);
  EXPECT_EQ(solve_profile().residual_fallbacks, 1);
  EXPECT_LE(solve_profile().residual_refinements, TangentSolver::kRefinementSteps);
  ASSERT_NE(strict.active(), nullptr);
  EXPECT_EQ(strict.active()->kind(), linalg::solver_available(linalg::SolverKind::kUmfpack)
                                         ? linalg::SolverKind::kUmfpack
                                         : linalg::SolverKind::kCholmodLdlt);
  EXPECT_LT(lower_residual(k, x, b), TangentSolver::kResidualTolerance);
  // The default tolerance: the LDL^T's own solution, no fallback, the same answer.
  TangentSolver normal(linalg::SolverKind::kAuto, false);
  ASSERT_TRUE(normal.factorize(k).ok());
  const VecX y = normal.solve(b);
  EXPECT_EQ(normal.n_residual_fallbacks(), 0);
  EXPECT_LT((x - y).norm(), 1e-8 * y.norm());
}

// A run's load steps share one TangentWorkspace: the pattern is laid out once for both
// steps, and the solution is the one of separate solves (same iterates, same numbers).
TEST(FormingTangentWorkspace, PatternKeptAcrossLoadStepsWithTheSameSolution) {
  Model model;
  model.add_ply(fixtures::rectangle_ply(20.0, 10.0, 1.0, 4, 2, 30.0), ti_model_material(fibre_from_layup_angle(30.0)));
  const VecX X = model.reference_positions();
  std::vector<PrescribedDof> half, full;  // edge x = 0 clamped, edge x = 20 pulled 0.2 mm along x
  const PlyMesh& ply = model.ply(0);
  for (Index s = 0; s < ply.n_surface_nodes(); ++s) {
    const double xs = ply.surface().node_position(s).x();
    if (std::abs(xs) > 1e-9 && std::abs(xs - 20.0) > 1e-9) continue;
    for (int layer = 0; layer < 2; ++layer)
      for (int d = 0; d < 4; ++d)
        for (int i = 0; i < 3; ++i) {
          const Index dof = model.dof(0, ply.node(s, layer), d, i);
          const double move = xs > 1.0 && d == 0 && i == 0 ? 0.2 : 0.0;
          half.push_back({dof, X(dof) + 0.5 * move});
          full.push_back({dof, X(dof) + move});
        }
  }
  StaticOptions kept;
  kept.workspace = std::make_shared<TangentWorkspace>();
  const StaticResult a1 = solve_static(model, X, half, VecX(), kept);
  const StaticResult a2 = solve_static(model, a1.positions, full, VecX(), kept);
  ASSERT_TRUE(a1.report.ok() && a2.report.ok()) << a1.report.brief() << " / " << a2.report.brief();
  EXPECT_EQ(kept.workspace->layouts(), 1);
  const StaticResult b1 = solve_static(model, X, half, VecX());
  const StaticResult b2 = solve_static(model, b1.positions, full, VecX());
  ASSERT_TRUE(b2.report.ok()) << b2.report.brief();
  EXPECT_EQ(a2.report.total_iterations, b2.report.total_iterations);
  EXPECT_LT(max_abs(MatX(a2.positions - b2.positions)), 1e-12 * max_abs(MatX(X)));
  EXPECT_GT(max_abs(MatX(a2.positions - X)), 0.1);  // it moved
  // Other free dofs: laid out anew.
  std::vector<PrescribedDof> fewer(full.begin(), full.begin() + 12);
  solve_static(model, X, fewer, VecX(), kept);
  EXPECT_EQ(kept.workspace->layouts(), 2);
}

}  // namespace
}  // namespace sf::forming
