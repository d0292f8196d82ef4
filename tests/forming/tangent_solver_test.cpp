// The Newton tangent's iterative solves (forming/solve/tangent_solver.hpp) against the
// direct one on a contact laminate: the [0,90]s dome case at 3 x 3 bricks a ply (four
// plies touching each other, the die and the holder; viscous inter-ply slip, so the
// tangent is unsymmetric).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/linalg/krylov.hpp"
#include "forming/case/build.hpp"
#include "forming/case/reader.hpp"
#include "forming/model/solve_profile.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

struct SmallDome {
  FormingCase spec;
  Problem problem;
  std::vector<bool> is_free;
  VecX x0, x1;  // the flat start and a state moved a little (the free z coordinates lowered)
  VecX previous;
  InteractionContext context;

  SmallDome() : spec(small_spec()), problem(build_problem(spec)) {
    const Model& model = problem.model;
    x0 = model.reference_positions();
    is_free = model.used_dofs();
    for (const PrescribedDof& p : problem.prescriptions.at(1.0 / spec.solver.steps))
      is_free[static_cast<std::size_t>(p.dof)] = false;
    // x1: every free coordinate moved by up to 0.01 um, so the contact gaps,
    // pressures and slip rates all change.
    x1 = x0;
    for (Index i = 0; i < x1.size(); ++i)
      if (is_free[static_cast<std::size_t>(i)]) x1(i) -= 1e-5 * std::sin(0.37 * static_cast<double>(i));
    previous = x0;
    context.previous = &previous;
    context.time = spec.solver.process_time / spec.solver.steps;
  }
  SmallDome(const SmallDome&) = delete;
  SmallDome& operator=(const SmallDome&) = delete;

  static FormingCase small_spec() {
    FormingCase s = load_case(std::string(SF_SOURCE_DIR) + "/data/forming/processes/dome_0_90s.yaml");
    for (CasePly& p : s.plies) p.n1 = p.n2 = 3;
    // Without the interface's tail (contact_law.hpp): with it every point within the search
    // distance has stiffness, so no pair closes inside the band (BandPattern below) and the
    // tangents are conditioned differently from the ones these checks were set on.
    for (CaseContact& c : s.contacts) c.law.normal.tail = 0.0;
    return s;
  }
};

linalg::SparseMatrix tangent_at(const SmallDome& d, const VecX& x, linalg::PatternAssembler& pa) {
  const Assembly a = d.problem.model.assemble_into(x, d.context, &pa);
  EXPECT_TRUE(a.ok) << a.message;
  return pa.matrix();
}

Eigen::VectorXd smooth_rhs(Index n) {
  Eigen::VectorXd b(n);
  for (Index i = 0; i < n; ++i) b(i) = std::cos(0.013 * static_cast<double>(i)) + 0.1 * std::sin(1.7 * i);
  return b;
}

double relative_residual(const linalg::SparseMatrix& k, linalg::Storage storage, const Eigen::VectorXd& x,
                         const Eigen::VectorXd& b) {
  Eigen::VectorXd kx(b.size());
  linalg::multiply(k, storage, x, kx);
  return (kx - b).norm() / b.norm();
}

// Both storages: the unsymmetric tangent (both triangles, UMFPACK) and its lower triangle
// as the symmetric path stores it (Cholesky, falling back to LU where indefinite).
class IterativeTangent : public ::testing::TestWithParam<bool> {};

TEST_P(IterativeTangent, AgreesWithTheDirectSolveWithAPreconditionerFromAnEarlierTangent) {
  const bool unsymmetric = GetParam();
  const SmallDome d;
  linalg::PatternAssembler pa = d.problem.model.make_pattern(d.is_free, !unsymmetric);
  const linalg::SparseMatrix k0 = tangent_at(d, d.x0, pa);
  const linalg::SparseMatrix k1 = tangent_at(d, d.x1, pa);
  ASSERT_EQ(k0.nonZeros(), k1.nonZeros()) << "the small move should keep the contact pattern";
  ASSERT_GT((k1 - k0).norm(), 1e-6 * k0.norm()) << "the two tangents should differ";
  const Index n = k1.rows();
  const std::vector<int> group = ply_groups(d.problem.model, pa.active_dofs());
  const Eigen::VectorXd b = smooth_rhs(n);

  TangentSolver direct(linalg::SolverKind::kAuto, unsymmetric, LinearMode::kDirect);
  ASSERT_TRUE(direct.factorize(k1).ok());
  const Eigen::VectorXd x_direct = direct.solve(b);

  solve_profile().reset();
  TangentSolver iterative(linalg::SolverKind::kAuto, unsymmetric, LinearMode::kIterative, group);
  ASSERT_TRUE(iterative.iterative());
  ASSERT_TRUE(iterative.factorize(k0).ok());
  const Eigen::VectorXd x0 = iterative.solve(b);  // preconditioner = k0 itself
  EXPECT_LE(solve_profile().krylov_iterations, 3);
  const long after_first = solve_profile().krylov_iterations;
  ASSERT_TRUE(iterative.factorize(k1).ok());  // keeps k0's factorisation
  const Eigen::VectorXd x_iterative = iterative.solve(b);
  const SolveProfile& p = solve_profile();
  EXPECT_EQ(p.preconditioner_factorizations, 1) << "k0's factorisation should have served for k1";
  EXPECT_EQ(p.direct_fallbacks, 0);
  EXPECT_GT(p.krylov_iterations - after_first, 1) << "a stale preconditioner needs some iterations";
  const linalg::Storage storage = unsymmetric ? linalg::Storage::kFull : linalg::Storage::kLower;
  EXPECT_LT(relative_residual(k1, storage, x_iterative, b), 1e-9);
  EXPECT_LT((x_iterative - x_direct).norm(), 1e-8 * x_direct.norm());
  EXPECT_GT((x0 - x_direct).norm(), 1e-6 * x_direct.norm()) << "k0's solution differs: the test can fail";
}

TEST_P(IterativeTangent, PerPlyPreconditionerAgreesWithTheDirectSolve) {
  // Per-ply blocks converge slowly under the stiff penalty coupling between plies; the
  // answer must still agree (GMRES, or its direct fallback, both counted).
  const bool unsymmetric = GetParam();
  const SmallDome d;
  linalg::PatternAssembler pa = d.problem.model.make_pattern(d.is_free, !unsymmetric);
  const linalg::SparseMatrix k1 = tangent_at(d, d.x1, pa);
  const std::vector<int> group = ply_groups(d.problem.model, pa.active_dofs());
  int n_groups = 0;
  for (int g : group) n_groups = std::max(n_groups, g + 1);
  EXPECT_EQ(n_groups, 4) << "one group per ply";
  const Eigen::VectorXd b = smooth_rhs(k1.rows());
  TangentSolver direct(linalg::SolverKind::kAuto, unsymmetric, LinearMode::kDirect);
  ASSERT_TRUE(direct.factorize(k1).ok());
  const Eigen::VectorXd x_direct = direct.solve(b);
  solve_profile().reset();
  TangentSolver ply(linalg::SolverKind::kAuto, unsymmetric, LinearMode::kIterativePly, group);
  ASSERT_TRUE(ply.factorize(k1).ok());
  const Eigen::VectorXd x = ply.solve(b);
  EXPECT_GT(solve_profile().krylov_iterations, 0);
  EXPECT_LT((x - x_direct).norm(), 1e-8 * x_direct.norm());
}

INSTANTIATE_TEST_SUITE_P(Storages, IterativeTangent, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? std::string("Unsymmetric") : std::string("LowerTriangle");
                         });

TEST(LinearMode, NamesRoundTripAndBadNamesSayWhatIsExpected) {
  for (LinearMode m : {LinearMode::kAuto, LinearMode::kDirect, LinearMode::kIterative, LinearMode::kIterativePly})
    EXPECT_EQ(parse_linear_mode(to_string(m)), m);
  try {
    parse_linear_mode("krylov", "--linear");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--linear"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("iterative"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("krylov"), std::string::npos);
  }
}

TEST(LinearMode, AutoIsDirectForSmallModels) {
  TangentSolver s(linalg::SolverKind::kAuto, true, LinearMode::kAuto, std::vector<int>(100, 0));
  EXPECT_FALSE(s.iterative());
}

}  // namespace
}  // namespace sf::forming

namespace sf::forming {
namespace {

// The top ply raised by 0.05 mm: its contact with the ply below opens (gap 0.05 mm, beyond
// the 0.005 mm engage gap and band of the case: no pressure, no viscous slip) but stays
// within the search distance.
VecX top_ply_raised(const SmallDome& d) {
  const Model& model = d.problem.model;
  VecX x = d.x0;
  const int top = model.n_bodies() - 1;
  for (Index node = 0; node < model.ply(top).n_nodes(); ++node) x(model.dof(top, node, 0, 2)) += 0.05;
  return x;
}

class BandPattern : public ::testing::TestWithParam<bool> {
 protected:
  void TearDown() override { Model::set_band_pattern(true); }
};

TEST_P(BandPattern, AContactClosingInsideTheSearchBandNeedsNoNewAnalysis) {
  const bool band = GetParam();
  Model::set_band_pattern(band);
  const SmallDome d;
  const VecX x_open = top_ply_raised(d);
  linalg::PatternAssembler pa = d.problem.model.make_pattern(d.is_free, false);
  TangentSolver solver(linalg::SolverKind::kAuto, true, LinearMode::kDirect);
  ASSERT_TRUE(d.problem.model.assemble_into(x_open, d.context, &pa).ok);
  const int open_generation = pa.generation();
  EXPECT_GE(open_generation, 1) << "the die and holder contacts grow the elements' pattern";
  const long open_nnz = pa.matrix().nonZeros();
  ASSERT_TRUE(solver.factorize(pa.matrix()).ok());
  // The ply closes on the one below: new contact entries between them.
  ASSERT_TRUE(d.problem.model.assemble_into(d.x0, d.context, &pa).ok);
  const linalg::SolveReport& r = solver.factorize(pa.matrix());
  ASSERT_TRUE(r.ok());
  if (band) {
    EXPECT_EQ(pa.generation(), open_generation) << "the closed pair was laid out while open";
    EXPECT_EQ(pa.matrix().nonZeros(), open_nnz);
    EXPECT_TRUE(r.reused_analysis);
  } else {
    EXPECT_GT(pa.generation(), open_generation) << "without the band the closing pair grows the pattern";
    EXPECT_FALSE(r.reused_analysis);
  }
  // The values do not depend on the layout: the same tangent as from a pattern made at x0.
  linalg::PatternAssembler fresh = d.problem.model.make_pattern(d.is_free, false);
  ASSERT_TRUE(d.problem.model.assemble_into(d.x0, d.context, &fresh).ok);
  EXPECT_EQ((linalg::SparseMatrix(pa.matrix() - fresh.matrix())).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(OnOff, BandPattern, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? std::string("BandLaidOut") : std::string("OnlyPresentEntries");
                         });

}  // namespace
}  // namespace sf::forming

namespace sf::forming {
namespace {

// The unsymmetric tangent of the small dome (viscous inter-ply slip between x0 and x1)
// with both triangles, the way the Newton loop stores it for an unsymmetric solver.
struct UnsymmetricDomeTangent {
  SmallDome d;
  linalg::PatternAssembler pa;
  UnsymmetricDomeTangent() : pa(d.problem.model.make_pattern(d.is_free, false)) {
    EXPECT_TRUE(d.problem.model.assemble_into(d.x1, d.context, &pa).ok);
  }
  const linalg::SparseMatrix& k() const { return pa.matrix(); }
  double asymmetry() const {
    const linalg::SparseMatrix kt = k().transpose();
    return linalg::SparseMatrix(k() - kt).norm() / k().norm();
  }
  // UMFPACK's solution (the LU of builds without MUMPS and of main before MUMPS's LU).
  Eigen::VectorXd umfpack_solution(const Eigen::VectorXd& b) const {
    TangentSolver umfpack(linalg::SolverKind::kUmfpack, true);
    EXPECT_TRUE(umfpack.factorize(k()).ok());
    return umfpack.solve(b).col(0);
  }
};

// kAuto with an unsymmetric tangent: MUMPS's LU when it is built in, the solution checked
// and the same as UMFPACK's; a second tangent of the same pattern keeps the analysis.
TEST(FormingTangentSolver, UnsymmetricTangentIsFactorisedByMumpsLuWithUmfpacksAnswer) {
  if (!linalg::solver_available(linalg::SolverKind::kMumps) || !linalg::solver_available(linalg::SolverKind::kUmfpack))
    GTEST_SKIP() << "this build has no MUMPS or no UMFPACK";
  const UnsymmetricDomeTangent t;
  ASSERT_GT(t.asymmetry(), 1e-8) << "the test needs an unsymmetric tangent";
  const Eigen::VectorXd b = smooth_rhs(t.k().rows());
  solve_profile().reset();
  TangentSolver solver(linalg::SolverKind::kAuto, true);
  EXPECT_FALSE(solver.lower());
  const linalg::SolveReport& r = solver.factorize(t.k());
  ASSERT_TRUE(r.ok()) << r.brief();
  EXPECT_EQ(r.used, linalg::SolverKind::kMumps);
  ASSERT_NE(solver.active(), nullptr);
  EXPECT_EQ(solver.active()->kind(), linalg::SolverKind::kMumps);
  const Eigen::VectorXd x = solver.solve(b).col(0);
  EXPECT_LT(relative_residual(t.k(), linalg::Storage::kFull, x, b), TangentSolver::kResidualTolerance);
  const Eigen::VectorXd y = t.umfpack_solution(b);
  EXPECT_LT((x - y).norm(), 1e-9 * y.norm());
  EXPECT_EQ(solver.n_lu_fallbacks(), 0);
  EXPECT_EQ(solve_profile().lu_checked_solves, 1);
  EXPECT_EQ(solve_profile().lu_fallbacks, 0);
  // The next iteration's tangent (same pattern, other values): the analysis is kept.
  linalg::PatternAssembler pa = t.d.problem.model.make_pattern(t.d.is_free, false);
  ASSERT_TRUE(t.d.problem.model.assemble_into(t.d.x0, t.d.context, &pa).ok);
  ASSERT_EQ(pa.matrix().nonZeros(), t.k().nonZeros());
  const linalg::SolveReport& r2 = solver.factorize(pa.matrix());
  ASSERT_TRUE(r2.ok()) << r2.brief();
  EXPECT_TRUE(r2.reused_analysis);
  EXPECT_EQ(r2.used, linalg::SolverKind::kMumps);
  EXPECT_LT(relative_residual(pa.matrix(), linalg::Storage::kFull, solver.solve(b).col(0), b),
            TangentSolver::kResidualTolerance);
}

// A MUMPS factorisation that fails (here: its working memory limited to 1 MB, far below
// what the tangent needs) is done by UMFPACK, with the same answer.
TEST(FormingTangentSolver, FailedMumpsLuFallsBackToUmfpack) {
  if (!linalg::solver_available(linalg::SolverKind::kMumps) || !linalg::solver_available(linalg::SolverKind::kUmfpack))
    GTEST_SKIP() << "this build has no MUMPS or no UMFPACK";
  const UnsymmetricDomeTangent t;
  const Eigen::VectorXd b = smooth_rhs(t.k().rows());
  solve_profile().reset();
  TangentSolver solver(linalg::SolverKind::kAuto, true);
  ASSERT_NE(solver.checked_lu(), nullptr);
  solver.checked_lu()->set_memory_limit(1);
  const linalg::SolveReport& r = solver.factorize(t.k());
  ASSERT_TRUE(r.ok()) << r.brief();
  EXPECT_EQ(r.used, linalg::SolverKind::kUmfpack);
  EXPECT_EQ(solver.checked_lu()->last_report().status, linalg::SolveReport::Status::kFailed);
  EXPECT_NE(solver.checked_lu()->last_report().message.find("ICNTL(23)"), std::string::npos)
      << solver.checked_lu()->last_report().message;
  EXPECT_EQ(solver.n_lu_fallbacks(), 1);
  EXPECT_EQ(solve_profile().lu_fallbacks, 1);
  const Eigen::VectorXd x = solver.solve(b).col(0);
  EXPECT_EQ(solver.active()->kind(), linalg::SolverKind::kUmfpack);
  EXPECT_EQ(solve_profile().lu_checked_solves, 0) << "UMFPACK's solutions are not checked";
  EXPECT_LT((x - t.umfpack_solution(b)).norm(), 1e-12 * x.norm());
  // Without the limit the next factorisation is MUMPS's again.
  solver.checked_lu()->set_memory_limit(0);
  ASSERT_TRUE(solver.factorize(t.k()).ok());
  EXPECT_EQ(solver.active()->kind(), linalg::SolverKind::kMumps);
}

// A MUMPS solution that fails the residual check (forced: tolerance 0) is redone by
// UMFPACK's LU of the same tangent, and that one is returned.
TEST(FormingTangentSolver, MumpsLuSolutionFailingTheCheckGoesToUmfpack) {
  if (!linalg::solver_available(linalg::SolverKind::kMumps) || !linalg::solver_available(linalg::SolverKind::kUmfpack))
    GTEST_SKIP() << "this build has no MUMPS or no UMFPACK";
  const UnsymmetricDomeTangent t;
  const Eigen::VectorXd b = smooth_rhs(t.k().rows());
  solve_profile().reset();
  TangentSolver strict(linalg::SolverKind::kAuto, true);
  strict.set_residual_tolerance(0.0);
  ASSERT_TRUE(strict.factorize(t.k()).ok());
  EXPECT_EQ(strict.active()->kind(), linalg::SolverKind::kMumps);
  const Eigen::VectorXd x = strict.solve(b).col(0);
  EXPECT_EQ(strict.n_lu_fallbacks(), 1);
  EXPECT_EQ(solve_profile().lu_fallbacks, 1);
  EXPECT_LE(solve_profile().lu_refinements, TangentSolver::kRefinementSteps);
  EXPECT_EQ(strict.active()->kind(), linalg::SolverKind::kUmfpack);
  EXPECT_LT((x - t.umfpack_solution(b)).norm(), 1e-12 * x.norm());
}

}  // namespace
}  // namespace sf::forming

namespace sf::forming {
namespace {

// TangentSolver::lay_out: the lower-triangle tangent laid out in the Cholesky's own order
// (CHOLMOD reads it in place) gives the solutions of the natural layout: the same back end
// on the dome's tangents (Cholesky, or the indefinite fallback that gets the matrix back in
// the natural order), across a pattern that grows after the layout (contact pairs).
TEST(FormingTangentSolver, PatternInTheCholeskysOrderGivesTheNaturalSolutions) {
  const SmallDome d;
  const Model& model = d.problem.model;
  linalg::PatternAssembler natural = model.make_pattern(d.is_free, true);
  linalg::PatternAssembler laid = model.make_pattern(d.is_free, true);
  TangentSolver reference(linalg::SolverKind::kAuto, false);
  TangentSolver solver(linalg::SolverKind::kAuto, false);
  ASSERT_TRUE(solver.lay_out(laid));
  EXPECT_FALSE(laid.order().empty());
  const Eigen::VectorXd b = smooth_rhs(natural.n_active());
  // No clock: no viscous slip, so the tangents are symmetric (the lower triangle is the
  // whole of them whatever the order; an unsymmetric tangent is stored with both).
  const InteractionContext still{};
  linalg::PatternAssembler full = model.make_pattern(d.is_free, false);
  ASSERT_TRUE(model.assemble_into(d.x1, still, &full).ok);
  const linalg::SparseMatrix kt = full.matrix().transpose();
  ASSERT_LT(linalg::SparseMatrix(full.matrix() - kt).norm(), 1e-12 * full.matrix().norm());
  int step = 0;
  for (const VecX* x : {&d.x0, &d.x1, &d.x0}) {
    SCOPED_TRACE(fmt::format("tangent {}", ++step));
    ASSERT_TRUE(model.assemble_into(*x, still, &natural).ok);
    const int generation = laid.generation();
    ASSERT_TRUE(model.assemble_into(*x, still, &laid).ok);
    if (step == 1) {
      EXPECT_GT(laid.generation(), generation) << "the contacts grow the pattern after the layout";
    }
    const linalg::SolveReport& r0 = reference.factorize(natural.matrix());
    const linalg::SolveReport& r1 = solver.factorize(laid.matrix());
    ASSERT_EQ(r0.ok(), r1.ok());
    ASSERT_TRUE(r1.ok()) << r1.brief();
    EXPECT_EQ(r1.used, r0.used) << r0.brief() << " / " << r1.brief();
    EXPECT_EQ(laid.matrix().nonZeros(), natural.matrix().nonZeros());
    const Eigen::VectorXd x0 = reference.solve(b), x1 = solver.solve(b);
    // Two elimination orders of one matrix agree to round-off times its condition number
    // (1.5e-12 relative on tangent 2 since the brick kernel's all-points kinematics).
    EXPECT_LT((x1 - x0).norm(), 1e-10 * x0.norm());
    EXPECT_LT(relative_residual(natural.matrix(), linalg::Storage::kLower, x1, b), 1e-9);
  }
  EXPECT_EQ(solver.n_indefinite(), reference.n_indefinite());
  // Indefinite (the diagonal lowered by a third of its mean, the same in any order): the
  // LDL^T and LU fallbacks get the matrix back in the natural order, the same solutions.
  double mean = 0.0;
  for (int c = 0; c < natural.matrix().outerSize(); ++c) mean += natural.matrix().coeff(c, c);
  mean /= natural.matrix().outerSize();
  for (linalg::PatternAssembler* pa : {&natural, &laid})
    for (int c = 0; c < pa->matrix().outerSize(); ++c) pa->matrix().coeffRef(c, c) -= 0.37 * mean;
  for (const double tolerance : {TangentSolver::kResidualTolerance, 0.0}) {  // 0: every solve to the LU
    SCOPED_TRACE(fmt::format("residual tolerance {}", tolerance));
    reference.set_residual_tolerance(tolerance);
    solver.set_residual_tolerance(tolerance);
    const linalg::SolveReport& r0 = reference.factorize(natural.matrix());
    const linalg::SolveReport& r1 = solver.factorize(laid.matrix());
    ASSERT_TRUE(r0.ok() && r1.ok()) << r0.brief() << " / " << r1.brief();
    EXPECT_NE(r1.used, linalg::SolverKind::kCholmod);
    EXPECT_EQ(r1.used, r0.used);
    const Eigen::VectorXd x0 = reference.solve(b), x1 = solver.solve(b);
    EXPECT_EQ(solver.active()->kind(), reference.active()->kind());
    EXPECT_LT((x1 - x0).norm(), 1e-12 * x0.norm());
  }
  EXPECT_EQ(solver.n_indefinite(), reference.n_indefinite());
  EXPECT_EQ(solver.n_residual_fallbacks(), reference.n_residual_fallbacks());
  // The iterative mode and unsymmetric tangents keep the natural layout.
  TangentSolver iterative(linalg::SolverKind::kAuto, false, LinearMode::kIterative,
                          ply_groups(model, laid.active_dofs()));
  EXPECT_FALSE(iterative.lay_out(laid));
  EXPECT_TRUE(laid.order().empty());
}

}  // namespace
}  // namespace sf::forming
