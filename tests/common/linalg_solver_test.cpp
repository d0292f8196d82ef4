// Tests for common/linalg: TripletAssembler, empty_rows and LinearSolver on
// every back end. Systems: the 5-point Laplacian on an m x m grid (SPD when
// shifted by +s, indefinite for s = -1) and a central-difference
// convection-diffusion operator (unsymmetric M-matrix).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "common/core/error.hpp"
#include "common/core/memory.hpp"
#include "common/linalg/pattern_assembler.hpp"
#include "common/linalg/solver.hpp"
#include "common/linalg/sparse.hpp"

namespace sf::linalg {
namespace {

constexpr double kResidualTolerance = 1e-10;  // ||A x - b|| / ||b|| per column
constexpr int kGridSize = 30;                 // 30 x 30 grid -> n = 900
constexpr int kNumRhs = 4;
constexpr unsigned kSeed = 20240611;

// The MUMPS kinds join in when the build has MUMPS (libmumps-seq-dev).
std::vector<SolverKind> with_mumps(std::vector<SolverKind> kinds, std::initializer_list<SolverKind> mumps) {
  for (const SolverKind k : mumps)
    if (solver_available(k)) kinds.push_back(k);
  return kinds;
}
const std::vector<SolverKind> kAllKinds =
    with_mumps({SolverKind::kAuto, SolverKind::kCholmod, SolverKind::kCholmodSimplicial, SolverKind::kUmfpack,
                SolverKind::kEigenLDLT, SolverKind::kEigenLU},
               {SolverKind::kMumps, SolverKind::kMumpsLdlt});
const std::vector<SolverKind> kLuKinds =
    with_mumps({SolverKind::kAuto, SolverKind::kUmfpack, SolverKind::kEigenLU}, {SolverKind::kMumps});

// Grid node (ix, iy) -> row; -1 outside the grid (Dirichlet boundary) or for
// the node `skip` (a DOF no element touches).
Index grid_dof(int m, int ix, int iy, Index skip = -1) {
  if (ix < 0 || iy < 0 || ix >= m || iy >= m) return -1;
  const Index dof = static_cast<Index>(iy) * m + ix;
  return dof == skip ? -1 : dof;
}

// 5-point stencil on an m x m grid (scaled by h^2): diagonal 4 + shift, and
// -1 - c_d to the neighbour in direction d. c = 0 gives the symmetric
// Laplacian; c_east = -c_west != 0 gives convection. Assembled per node with
// add_block so negative (boundary) columns are skipped by the assembler.
SparseMatrix stencil_2d(int m, double shift, double c_x = 0.0, double c_y = 0.0, Index skip = -1) {
  const Index n = static_cast<Index>(m) * m;
  TripletAssembler assembler(n, n);
  assembler.reserve(5 * n);
  for (int iy = 0; iy < m; ++iy) {
    for (int ix = 0; ix < m; ++ix) {
      const std::vector<Index> row = {grid_dof(m, ix, iy, skip)};
      const std::vector<Index> cols = {grid_dof(m, ix, iy, skip), grid_dof(m, ix + 1, iy, skip),
                                       grid_dof(m, ix - 1, iy, skip), grid_dof(m, ix, iy + 1, skip),
                                       grid_dof(m, ix, iy - 1, skip)};
      Eigen::RowVectorXd values(5);
      values << 4.0 + shift, -1.0 + c_x, -1.0 - c_x, -1.0 + c_y, -1.0 - c_y;
      assembler.add_block(row, cols, values);
    }
  }
  return assembler.compress();
}

SparseMatrix laplacian_2d(int m, double shift) { return stencil_2d(m, shift); }

// -Laplace(u) + (b_x, b_y) . grad(u) with central differences, h = 1/(m+1);
// cell Peclet number below 1 keeps it an M-matrix (nonsingular).
SparseMatrix convection_diffusion_2d(int m, double b_x, double b_y) {
  const double h = 1.0 / (m + 1);
  return stencil_2d(m, 0.0, 0.5 * h * b_x, 0.5 * h * b_y);
}

Eigen::MatrixXd random_rhs(Index n, int n_rhs, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  Eigen::MatrixXd b(n, n_rhs);
  for (Eigen::Index j = 0; j < b.cols(); ++j) {
    for (Eigen::Index i = 0; i < b.rows(); ++i) b(i, j) = dist(gen);
  }
  return b;
}

// Largest ||A x_j - b_j|| / ||b_j|| over the columns.
double max_relative_residual(const SparseMatrix& a, const Eigen::MatrixXd& x, const Eigen::MatrixXd& b) {
  const Eigen::MatrixXd r = a * x - b;
  double worst = 0.0;
  for (Eigen::Index j = 0; j < b.cols(); ++j) {
    worst = std::max(worst, r.col(j).norm() / b.col(j).norm());
  }
  return worst;
}

// Factorises a, solves kNumRhs right-hand sides at once, checks the residual
// and records it (console and XML) under `label`.
void expect_solves(LinearSolver& solver, const SparseMatrix& a, const std::string& label) {
  const SolveReport& report = solver.factorize(a);
  ASSERT_TRUE(report.ok()) << label << ": " << report.brief();
  const Eigen::MatrixXd b = random_rhs(a.rows(), kNumRhs, kSeed);
  const Eigen::MatrixXd x = solver.solve(b);
  ASSERT_EQ(x.rows(), a.rows());
  ASSERT_EQ(x.cols(), kNumRhs);
  const double residual = max_relative_residual(a, x, b);
  EXPECT_LT(residual, kResidualTolerance) << label << ": " << solver.last_report().brief();
  std::printf("[ residual ] %-40s %.3e\n", label.c_str(), residual);
  ::testing::Test::RecordProperty("residual " + label, fmt::format("{:.3e}", residual));
}

// ---------------------------------------------------------------------------
// TripletAssembler and empty_rows

TEST(SparseAssembler, SumsDuplicateEntries) {
  TripletAssembler assembler(3, 3);
  assembler.add(0, 0, 1.0);
  assembler.add(0, 0, 2.5);
  assembler.add(2, 1, -1.0);
  assembler.add(2, 1, 4.0);
  assembler.add(1, 2, 7.0);
  EXPECT_EQ(assembler.n_triplets(), 5);
  const SparseMatrix m = assembler.compress();
  EXPECT_TRUE(m.isCompressed());
  EXPECT_EQ(m.nonZeros(), 3);
  EXPECT_DOUBLE_EQ(m.coeff(0, 0), 3.5);
  EXPECT_DOUBLE_EQ(m.coeff(2, 1), 3.0);
  EXPECT_DOUBLE_EQ(m.coeff(1, 2), 7.0);
  EXPECT_DOUBLE_EQ(m.coeff(1, 1), 0.0);
}

TEST(SparseAssembler, AddBlockSkipsNegativeIndicesAndMatchesDense) {
  // Two overlapping 3 x 3 "elements" on 4 DOFs; DOF -1 is constrained.
  Eigen::Matrix3d k1;
  k1 << 2, -1, 0.5, -1, 3, 0, 0.5, 0, 1;
  Eigen::Matrix3d k2;
  k2 << 5, 1, -2, 1, 6, 0.25, -2, 0.25, 7;
  const std::vector<Index> dofs1 = {0, 1, -1};
  const std::vector<Index> dofs2 = {1, 3, 2};

  TripletAssembler assembler(4, 4);
  assembler.reserve(18);
  assembler.add_block(dofs1, dofs1, k1);
  assembler.add_block(dofs2, dofs2, k2);
  assembler.add(-1, 2, 100.0);  // skipped
  assembler.add(3, -5, 100.0);  // skipped
  EXPECT_EQ(assembler.n_triplets(), 4 + 9);

  Eigen::Matrix4d expected = Eigen::Matrix4d::Zero();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      if (dofs1[a] >= 0 && dofs1[b] >= 0) expected(dofs1[a], dofs1[b]) += k1(a, b);
      expected(dofs2[a], dofs2[b]) += k2(a, b);
    }
  }
  const Eigen::MatrixXd dense = Eigen::MatrixXd(assembler.compress());
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      EXPECT_DOUBLE_EQ(dense(i, j), expected(i, j)) << "entry (" << i << ", " << j << ")";
    }
  }
}

TEST(SparseAssembler, RectangularCompressTwiceAndClear) {
  TripletAssembler assembler(2, 5);
  assembler.add(1, 4, 2.0);
  const SparseMatrix first = assembler.compress();
  assembler.add(1, 4, 3.0);
  const SparseMatrix second = assembler.compress();
  EXPECT_EQ(first.rows(), 2);
  EXPECT_EQ(first.cols(), 5);
  EXPECT_DOUBLE_EQ(first.coeff(1, 4), 2.0);
  EXPECT_DOUBLE_EQ(second.coeff(1, 4), 5.0);
  assembler.clear();
  EXPECT_EQ(assembler.n_triplets(), 0);
  EXPECT_EQ(assembler.compress().nonZeros(), 0);
  EXPECT_EQ(assembler.n_rows(), 2);
}

TEST(SparseAssembler, KeepsExplicitZerosSoThePatternIsValueIndependent) {
  TripletAssembler assembler(2, 2);
  assembler.add(0, 1, 1.0);
  assembler.add(0, 1, -1.0);  // sums to an explicit zero, kept in the pattern
  assembler.add(1, 1, 0.0);
  const SparseMatrix m = assembler.compress();
  EXPECT_EQ(m.nonZeros(), 2);
  // Rows holding only zeros count as empty.
  EXPECT_EQ(empty_rows(m), (std::vector<Index>{0, 1}));
}

TEST(SparseEmptyRows, FindsDofsNoElementTouches) {
  const SparseMatrix full = laplacian_2d(5, 0.0);
  EXPECT_TRUE(empty_rows(full).empty());
  const Index skipped = 12;
  const SparseMatrix holed = stencil_2d(5, 0.0, 0.0, 0.0, skipped);
  EXPECT_EQ(empty_rows(holed), (std::vector<Index>{skipped}));
  EXPECT_TRUE(empty_rows(SparseMatrix(0, 0)).empty());
  EXPECT_EQ(empty_rows(SparseMatrix(3, 2)), (std::vector<Index>{0, 1, 2}));
}

// ---------------------------------------------------------------------------
// Solver names

TEST(LinalgSolverKind, ToStringAndParseRoundTrip) {
  for (const SolverKind kind : kAllKinds) {
    EXPECT_EQ(parse_solver_kind(to_string(kind)), kind) << to_string(kind);
    EXPECT_TRUE(solver_available(kind)) << to_string(kind);
  }
  EXPECT_EQ(to_string(SolverKind::kEigenLDLT), "eigen-ldlt");
  EXPECT_EQ(to_string(SolverKind::kEigenLU), "eigen-lu");
  EXPECT_EQ(parse_solver_kind("umfpack"), SolverKind::kUmfpack);
  EXPECT_EQ(to_string(MatrixProperty::kSymmetricIndefinite), "symmetric-indefinite");
  EXPECT_EQ(to_string(SolveReport::Status::kSingular), "singular");
}

TEST(LinalgSolverKind, UnknownNameThrowsInputErrorNamingWhere) {
  EXPECT_THROW(parse_solver_kind("pardiso"), InputError);
  EXPECT_THROW(parse_solver_kind("CHOLMOD"), InputError);  // names are exact, lower case
  EXPECT_THROW(parse_solver_kind(""), InputError);
  try {
    parse_solver_kind("superlu", "--solver");
    FAIL() << "expected sf::InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--solver: ", 0), 0u) << what;
    EXPECT_NE(what.find("'superlu'"), std::string::npos) << what;
    EXPECT_NE(what.find("eigen-ldlt"), std::string::npos) << what;
  }
}

TEST(LinalgSolverKind, SymmetricBackendsRejectUnsymmetricProperty) {
  EXPECT_THROW(LinearSolver(SolverKind::kCholmod, MatrixProperty::kUnsymmetric), InputError);
  EXPECT_THROW(LinearSolver(SolverKind::kCholmodSimplicial, MatrixProperty::kUnsymmetric), InputError);
  EXPECT_THROW(LinearSolver(SolverKind::kEigenLDLT, MatrixProperty::kUnsymmetric), InputError);
  EXPECT_NO_THROW(LinearSolver(SolverKind::kUmfpack, MatrixProperty::kUnsymmetric));
  EXPECT_NO_THROW(LinearSolver(SolverKind::kEigenLU, MatrixProperty::kSymmetricPositiveDefinite));
}

TEST(LinalgSolverKind, AutoResolvesFromMatrixProperty) {
  EXPECT_EQ(LinearSolver(SolverKind::kAuto, MatrixProperty::kSymmetricPositiveDefinite).kind(), SolverKind::kCholmod);
  EXPECT_EQ(LinearSolver(SolverKind::kAuto, MatrixProperty::kSymmetricIndefinite).kind(), SolverKind::kUmfpack);
  EXPECT_EQ(LinearSolver(SolverKind::kAuto, MatrixProperty::kUnsymmetric).kind(), SolverKind::kUmfpack);
  EXPECT_EQ(LinearSolver(SolverKind::kEigenLU).kind(), SolverKind::kEigenLU);
}

// ---------------------------------------------------------------------------
// Solving

TEST(LinalgSolver, EveryBackendSolvesSpdSystemWithSeveralRhs) {
  const SparseMatrix a = laplacian_2d(kGridSize, 1.0);  // spectrum in (1, 9)
  ASSERT_EQ(a.rows(), kGridSize * kGridSize);
  for (const SolverKind kind : kAllKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind, MatrixProperty::kSymmetricPositiveDefinite);
    expect_solves(solver, a, "spd " + to_string(kind));
    EXPECT_EQ(solver.last_report().used, solver.kind());
    EXPECT_EQ(solver.last_report().n_rows, a.rows());
    EXPECT_EQ(solver.last_report().n_nonzeros, a.nonZeros());
    EXPECT_FALSE(solver.last_report().reused_analysis);
  }
}

TEST(LinalgSolver, LuBackendsSolveUnsymmetricConvectionDiffusion) {
  const SparseMatrix a = convection_diffusion_2d(kGridSize, 40.0, -25.0);
  const double asymmetry = (a - SparseMatrix(a.transpose())).norm() / a.norm();
  ASSERT_GT(asymmetry, 0.1);
  for (const SolverKind kind : kLuKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind, MatrixProperty::kUnsymmetric);
    expect_solves(solver, a, "unsymmetric " + to_string(kind));
  }
}

TEST(LinalgSolver, IndefiniteSymmetricSolvedByPivotingBackends) {
  // 73 of 900 eigenvalues negative; min |lambda| = 0.017.
  const SparseMatrix a = laplacian_2d(kGridSize, -1.0);
  for (const SolverKind kind :
       with_mumps({SolverKind::kAuto, SolverKind::kUmfpack, SolverKind::kEigenLDLT, SolverKind::kEigenLU},
                  {SolverKind::kMumps, SolverKind::kMumpsLdlt})) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind, MatrixProperty::kSymmetricIndefinite);
    expect_solves(solver, a, "indefinite " + to_string(kind));
  }
}

// A symmetric indefinite matrix no LDL^T without pivoting can factorise: the 900-unknown
// indefinite Laplacian (73 negative eigenvalues) beside five decoupled 2 x 2 blocks
// [[0, 1], [1, 0]] (eigenvalues +-1), whose first pivot is zero in any elimination order.
// Cholesky and the unpivoted LDL^T (CHOLMOD's, Eigen's) break down; MUMPS's LDL^T with
// 2 x 2 pivots solves it and counts the negative eigenvalues (Sylvester's inertia).
TEST(LinalgSolver, MumpsLdltSolvesWhereCholeskyAndUnpivotedLdltBreakDown) {
  if (!solver_available(SolverKind::kMumpsLdlt)) GTEST_SKIP() << "this build has no MUMPS";
  const SparseMatrix lap = laplacian_2d(kGridSize, -1.0);
  const Index n0 = lap.rows(), n = n0 + 10;
  TripletAssembler t(n, n);
  for (int j = 0; j < lap.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(lap, j); it; ++it) t.add(it.row(), it.col(), it.value());
  for (Index b = 0; b < 5; ++b) {
    t.add(n0 + 2 * b, n0 + 2 * b + 1, 1.0);
    t.add(n0 + 2 * b + 1, n0 + 2 * b, 1.0);
  }
  const SparseMatrix a = t.compress();
  const SparseMatrix lower = a.triangularView<Eigen::Lower>();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig{Eigen::MatrixXd(a)};
  const int negative = static_cast<int>((eig.eigenvalues().array() < 0.0).count());
  ASSERT_EQ(negative, 73 + 5);
  ASSERT_GT(eig.eigenvalues().cwiseAbs().minCoeff(), 1e-3);  // nonsingular

  for (const SolverKind kind : {SolverKind::kCholmod, SolverKind::kCholmodLdlt, SolverKind::kEigenLDLT}) {
    LinearSolver unpivoted(kind, kind == SolverKind::kCholmod ? MatrixProperty::kSymmetricPositiveDefinite
                                                              : MatrixProperty::kSymmetricIndefinite);
    EXPECT_EQ(unpivoted.factorize(lower).status, SolveReport::Status::kSingular) << to_string(kind);
  }
  LinearSolver mumps(SolverKind::kMumpsLdlt, MatrixProperty::kSymmetricIndefinite);
  for (const SparseMatrix* m : {&lower, &a}) {  // its lower triangle, or both (the upper one is not read)
    const SolveReport& r = mumps.factorize(*m);
    ASSERT_TRUE(r.ok()) << r.brief();
    EXPECT_EQ(r.negative_pivots, negative);
    EXPECT_GT(r.factor_flops, 0.0);
    EXPECT_GT(r.factor_nonzeros, 0.0);
    EXPECT_FALSE(r.ordering.empty());
    const Eigen::MatrixXd b = random_rhs(n, kNumRhs, kSeed);
    const Eigen::MatrixXd x = mumps.solve(b);
    EXPECT_LT(max_relative_residual(a, x, b), kResidualTolerance) << r.brief();
    // residual(): B - A X from the solver's own copy, read as its lower triangle.
    EXPECT_LT((mumps.residual(b, x) - (b - a * x)).norm(), 1e-12 * b.norm());
  }
  // The same values again: the analysis is kept.
  EXPECT_TRUE(mumps.factorize(a).reused_analysis);
}

TEST(LinalgSolver, RefactorizeReusesAnalysisOnlyForTheSamePattern) {
  const SparseMatrix a1 = laplacian_2d(kGridSize, 0.5);
  const SparseMatrix a2 = laplacian_2d(kGridSize, 3.0) * 0.25;  // same pattern, new values
  const SparseMatrix a3 = laplacian_2d(kGridSize - 7, 1.0);     // new size and pattern
  for (const SolverKind kind : kAllKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind);
    expect_solves(solver, a1, "refactorize a1 " + to_string(kind));
    EXPECT_FALSE(solver.last_report().reused_analysis);
    expect_solves(solver, a2, "refactorize a2 " + to_string(kind));
    EXPECT_TRUE(solver.last_report().reused_analysis);
    EXPECT_EQ(solver.last_report().analyze_seconds, 0.0);
    expect_solves(solver, a3, "refactorize a3 " + to_string(kind));
    EXPECT_FALSE(solver.last_report().reused_analysis);
  }
}

// Every fill-reducing ordering of the CHOLMOD back ends solves the system; changing
// the ordering drops the analysis; names round-trip and a wrong one names the option.
TEST(LinalgSolver, EveryCholmodOrderingSolves) {
  if (!solver_available(SolverKind::kCholmod)) GTEST_SKIP() << "no SuiteSparse";
  const SparseMatrix a = laplacian_2d(kGridSize, 1.0);
  for (const SolverKind kind : {SolverKind::kCholmod, SolverKind::kCholmodSimplicial, SolverKind::kCholmodLdlt})
    for (const Ordering o : {Ordering::kDefault, Ordering::kAmd, Ordering::kMetis, Ordering::kNesdis}) {
      SCOPED_TRACE(to_string(kind) + " " + to_string(o));
      LinearSolver solver(kind, MatrixProperty::kSymmetricPositiveDefinite);
      expect_solves(solver, a, "ordering");
      solver.set_ordering(o);
      EXPECT_EQ(solver.ordering(), o);
      expect_solves(solver, a, "ordering");
      EXPECT_EQ(solver.last_report().reused_analysis, o == Ordering::kDefault);
      EXPECT_EQ(parse_ordering(to_string(o)), o);
    }
  try {
    parse_ordering("rcm", "--ordering");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--ordering: unknown fill-reducing ordering 'rcm'"), std::string::npos)
        << e.what();
  }
  EXPECT_GE(factorisation_threads(), 1);
  EXPECT_FALSE(blas_description().empty());
}

// kCholmod permutes the matrix itself (B = tril(P A P^T) through a map made at the analysis)
// rather than leaving it to CHOLMOD: an irregular SPD pattern given as its lower triangle and
// as both triangles, each ordering, and new values on the kept analysis, give the solution
// of a dense Cholesky of the same matrix; the map is rebuilt when the pattern changes.
TEST(LinalgSolver, SupernodalCholmodOnItsOwnPermutationMatchesDenseCholesky) {
  if (!solver_available(SolverKind::kCholmod)) GTEST_SKIP() << "no SuiteSparse";
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_spd = [&](int n, double density, double scale) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
    std::uniform_real_distribution<double> pick(0.0, 1.0);
    for (int j = 0; j < n; ++j)
      for (int i = j + 1; i < n; ++i)
        if (pick(rng) < density) d(i, j) = d(j, i) = scale * u(rng);
    for (int i = 0; i < n; ++i) d(i, i) = d.row(i).cwiseAbs().sum() + 1.0 + pick(rng);  // diagonally dominant
    return d;
  };
  const int n = 300;
  const Eigen::MatrixXd d1 = random_spd(n, 0.03, 1.0);
  Eigen::MatrixXd d2 = d1;  // same pattern, other values
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (d1(i, j) != 0.0 && i != j) d2(i, j) = d2(j, i) = 0.5 * d1(i, j) * (1.0 + 0.3 * std::sin(i + 2.0 * j + i * j));
  const Eigen::MatrixXd d3 = random_spd(n - 40, 0.05, 2.0);  // another size and pattern
  const Eigen::MatrixXd b = Eigen::MatrixXd::NullaryExpr(n, kNumRhs, [&] { return u(rng); });
  for (const Ordering o : {Ordering::kDefault, Ordering::kAmd, Ordering::kMetis, Ordering::kNesdis})
    for (const bool lower_only : {true, false}) {
      SCOPED_TRACE(to_string(o) + (lower_only ? " lower triangle" : " both triangles"));
      LinearSolver solver(SolverKind::kCholmod, MatrixProperty::kSymmetricPositiveDefinite);
      solver.set_ordering(o);
      int step = 0;
      for (const Eigen::MatrixXd* d : std::vector<const Eigen::MatrixXd*>{&d1, &d2, &d3}) {
        SCOPED_TRACE(fmt::format("matrix {}", ++step));
        const Eigen::MatrixXd full = *d;
        const SparseMatrix a = lower_only ? SparseMatrix(full.triangularView<Eigen::Lower>().toDenseMatrix().sparseView())
                                          : SparseMatrix(full.sparseView());
        ASSERT_TRUE(solver.factorize(a).ok()) << solver.last_report().brief();
        EXPECT_EQ(solver.last_report().reused_analysis, step == 2);
        const Eigen::MatrixXd rhs = b.topRows(full.rows());
        const Eigen::MatrixXd x = solver.solve(rhs);
        const Eigen::MatrixXd expected = full.llt().solve(rhs);
        EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
      }
    }
}

// UMFPACK takes the orderings too, and every SuiteSparse back end reports the size of its
// factor and the ordering it used (the dome benchmark prints them).
TEST(LinalgSolver, UmfpackOrderingsSolveAndFactorSizesAreReported) {
  if (!solver_available(SolverKind::kUmfpack)) GTEST_SKIP() << "no SuiteSparse";
  const SparseMatrix a = convection_diffusion_2d(kGridSize, 0.3, -0.2);
  double flops_amd = 0.0;
  for (const Ordering o : {Ordering::kAmd, Ordering::kMetis}) {
    SCOPED_TRACE(to_string(o));
    LinearSolver solver(SolverKind::kUmfpack, MatrixProperty::kUnsymmetric);
    solver.set_ordering(o);
    expect_solves(solver, a, "umfpack ordering");
    const SolveReport& r = solver.last_report();
    EXPECT_EQ(r.ordering.rfind(o == Ordering::kAmd ? "amd" : "metis", 0), 0u) << r.ordering;
    EXPECT_GT(r.factor_nonzeros, static_cast<double>(a.rows()));  // L and U with their diagonals at least
    EXPECT_GT(r.factor_flops, 0.0);
    if (o == Ordering::kAmd)
      flops_amd = r.factor_flops;
    else
      EXPECT_NE(r.factor_flops, flops_amd);  // another ordering, another factor
  }
  LinearSolver chol(SolverKind::kCholmod, MatrixProperty::kSymmetricPositiveDefinite);
  chol.set_ordering(Ordering::kAmd);
  const SparseMatrix spd = laplacian_2d(kGridSize, 1.0);
  expect_solves(chol, spd, "cholmod sizes");
  EXPECT_EQ(chol.last_report().ordering, "amd");
  EXPECT_GE(chol.last_report().factor_nonzeros, static_cast<double>(spd.rows()));
}

// The program's start-up setting (common/core/memory.hpp): once in force, a block of the
// size of a factorisation's working memory comes from the heap, not from a fresh mapping
// that would be page-faulted in again at every Newton iteration.
TEST(LinalgSolver, FreedMemoryIsKeptWhenTheProgramAsks) {
  const bool kept = sf::keep_freed_memory();
  EXPECT_EQ(kept, sf::keep_freed_memory());
#if defined(__GLIBC__)
  const bool user_tuned = std::getenv("GLIBC_TUNABLES") || std::getenv("MALLOC_MMAP_MAX_") ||
                          std::getenv("MALLOC_MMAP_THRESHOLD_") || std::getenv("MALLOC_TRIM_THRESHOLD_");
  if (user_tuned) GTEST_SKIP() << "malloc is tuned by the environment: the setting is left alone";
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "the address sanitizer replaces malloc: mallopt does not apply (kept = " << kept << ")";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
  GTEST_SKIP() << "a sanitizer replaces malloc: mallopt does not apply (kept = " << kept << ")";
#endif
#endif
  ASSERT_TRUE(kept);
  const std::size_t mapped_before = mallinfo2().hblkhd;
  std::vector<char> block(std::size_t{64} << 20, 1);
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before) << "a 64 MB block was mapped separately";
  EXPECT_EQ(block[12345], 1);
#endif
}

TEST(LinalgSolver, AnalyzePatternThenFactorizeReusesIt) {
  const SparseMatrix a = laplacian_2d(kGridSize, 2.0);
  for (const SolverKind kind : kAllKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind);
    const SolveReport& analysed = solver.analyze_pattern(a);
    EXPECT_EQ(analysed.status, SolveReport::Status::kNotFactorized) << analysed.brief();
    EXPECT_FALSE(solver.is_factorized());
    expect_solves(solver, a, "analyse+factorize " + to_string(kind));
    EXPECT_TRUE(solver.last_report().reused_analysis);
  }
}

TEST(LinalgSolver, CholmodReportsIndefiniteMatrixAsSingularWithoutThrowing) {
  const SparseMatrix indefinite = laplacian_2d(kGridSize, -1.0);
  for (const SolverKind kind : {SolverKind::kCholmod, SolverKind::kCholmodSimplicial, SolverKind::kAuto}) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind, MatrixProperty::kSymmetricPositiveDefinite);
    SolveReport report;
    EXPECT_NO_THROW(report = solver.factorize(indefinite));
    EXPECT_EQ(report.status, SolveReport::Status::kSingular) << report.brief();
    EXPECT_FALSE(report.ok());
    EXPECT_FALSE(solver.is_factorized());
    EXPECT_NE(report.message.find("not positive definite"), std::string::npos) << report.message;
    EXPECT_NE(report.brief().find("singular"), std::string::npos) << report.brief();
    // The same solver recovers once the values are positive definite again.
    expect_solves(solver, laplacian_2d(kGridSize, 1.0), "after indefinite " + to_string(kind));
    EXPECT_TRUE(solver.last_report().reused_analysis);
  }
}

TEST(LinalgSolver, UnpinnedDofIsSingularUntilPinned) {
  // DOF 17 is touched by no element: an empty row and column.
  const Index skipped = 17;
  const SparseMatrix holed = stencil_2d(10, 1.0, 0.0, 0.0, skipped);
  const std::vector<Index> empty = empty_rows(holed);
  ASSERT_EQ(empty, (std::vector<Index>{skipped}));

  // Pin the empty rows with a unit diagonal.
  TripletAssembler pin(holed.rows(), holed.cols());
  for (const Index row : empty) pin.add(row, row, 1.0);
  const SparseMatrix pinned = holed + pin.compress();

  for (const SolverKind kind : kAllKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver solver(kind);
    SolveReport report;
    EXPECT_NO_THROW(report = solver.factorize(holed));
    EXPECT_EQ(report.status, SolveReport::Status::kSingular) << report.brief();
    EXPECT_FALSE(report.message.empty());
    expect_solves(solver, pinned, "pinned " + to_string(kind));
  }
}

TEST(LinalgSolver, ReportsBeforeFactorizationAndForNonSquareInput) {
  LinearSolver solver(SolverKind::kUmfpack, MatrixProperty::kUnsymmetric);
  EXPECT_EQ(solver.last_report().status, SolveReport::Status::kNotFactorized);
  EXPECT_EQ(solver.last_report().used, SolverKind::kUmfpack);
  EXPECT_FALSE(solver.is_factorized());
#ifdef NDEBUG
  // Release builds: solve() before factorize() returns NaNs of the right shape.
  const Eigen::MatrixXd x = solver.solve(Eigen::MatrixXd::Ones(0, 2));
  EXPECT_EQ(x.cols(), 2);
#endif
  SparseMatrix rectangular(4, 3);
  rectangular.insert(0, 0) = 1.0;
  const SolveReport& report = solver.factorize(rectangular);
  EXPECT_EQ(report.status, SolveReport::Status::kFailed);
  EXPECT_NE(report.message.find("not square"), std::string::npos) << report.message;
}

TEST(LinalgSolver, EmptySystemIsTriviallyOk) {
  LinearSolver solver;
  EXPECT_TRUE(solver.factorize(SparseMatrix(0, 0)).ok());
  const Eigen::MatrixXd x = solver.solve(Eigen::MatrixXd(0, 3));
  EXPECT_EQ(x.rows(), 0);
  EXPECT_EQ(x.cols(), 3);
}

TEST(LinalgSolver, FactorisationOwnsItsMatrixAndSurvivesMoves) {
  // UMFPACK's solve reads A again; the solver must not point into the caller's
  // (here temporary, uncompressed) matrix, and must survive being moved.
  for (const SolverKind kind : kAllKinds) {
    SCOPED_TRACE(to_string(kind));
    LinearSolver original(kind);
    {
      SparseMatrix temporary = laplacian_2d(kGridSize, 1.0);
      temporary.uncompress();
      ASSERT_TRUE(original.factorize(temporary).ok());
      temporary.setZero();  // clobber the caller's copy
    }
    LinearSolver moved(std::move(original));
    LinearSolver assigned(SolverKind::kEigenLU);
    assigned = std::move(moved);
    ASSERT_TRUE(assigned.is_factorized());

    const SparseMatrix a = laplacian_2d(kGridSize, 1.0);
    const Eigen::MatrixXd b = random_rhs(a.rows(), kNumRhs, kSeed + 1);
    const double residual = max_relative_residual(a, assigned.solve(b), b);
    EXPECT_LT(residual, kResidualTolerance);
    std::printf("[ residual ] %-40s %.3e\n", ("moved " + to_string(kind)).c_str(), residual);
  }
}

TEST(LinalgSolver, SolveAcceptsBlocksAndVectorsAndRecordsTiming) {
  const SparseMatrix a = laplacian_2d(kGridSize, 1.0);
  LinearSolver solver(SolverKind::kCholmod);
  ASSERT_TRUE(solver.factorize(a).ok());
  const Eigen::MatrixXd b = random_rhs(a.rows(), 6, kSeed + 2);
  // A non-contiguous block of columns and a single vector give the same answers
  // as solving all columns at once.
  const Eigen::MatrixXd x_all = solver.solve(b);
  const Eigen::MatrixXd x_block = solver.solve(b.middleCols(2, 3));
  const Eigen::VectorXd b_vec = b.col(5);
  const Eigen::MatrixXd x_vec = solver.solve(b_vec);
  EXPECT_LT((x_block - x_all.middleCols(2, 3)).norm(), 1e-12 * x_all.norm());
  EXPECT_LT((x_vec - x_all.col(5)).norm(), 1e-12 * x_all.norm());
  EXPECT_LT(max_relative_residual(a, x_all, b), kResidualTolerance);

  const SolveReport& report = solver.last_report();
  EXPECT_GE(report.factor_seconds, 0.0);
  EXPECT_GE(report.solve_seconds, 0.0);
  const std::string brief = report.brief();
  EXPECT_EQ(brief.find('\n'), std::string::npos);
  EXPECT_EQ(brief.rfind("cholmod n=900 ", 0), 0u) << brief;
  EXPECT_NE(brief.find(": ok"), std::string::npos) << brief;
}

// gsa's fit solves two penalties at once, one simplicial CHOLMOD solver per
// thread: concurrent runs must give exactly what one thread gives.
TEST(LinalgSolver, SimplicialCholmodSolversRunConcurrently) {
  constexpr int kPairs = 20;
  constexpr SolverKind kind = SolverKind::kCholmodSimplicial;
  std::vector<SparseMatrix> matrices;
  for (int k = 0; k < 2 * kPairs; ++k) matrices.push_back(laplacian_2d(kGridSize, 0.5 + 0.1 * k));
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(matrices[0].rows(), 2);
  auto solve = [&](LinearSolver& solver, const SparseMatrix& a) {
    EXPECT_TRUE(solver.factorize(a).ok());
    return Eigen::MatrixXd(solver.solve(b));
  };
  std::vector<Eigen::MatrixXd> sequential, concurrent(matrices.size());
  {
    LinearSolver solver(kind);
    for (const SparseMatrix& a : matrices) sequential.push_back(solve(solver, a));
  }
  LinearSolver first(kind), second(kind);
  for (int k = 0; k < kPairs; ++k) {
    std::thread other([&] { concurrent[2 * k + 1] = solve(second, matrices[2 * k + 1]); });
    concurrent[2 * k] = solve(first, matrices[2 * k]);
    other.join();
  }
  for (std::size_t k = 0; k < matrices.size(); ++k) EXPECT_EQ(sequential[k], concurrent[k]) << "system " << k;
}

}  // namespace
}  // namespace sf::linalg

namespace sf::linalg {
namespace {

// Elements of 2..6 random dofs (some repeated: a collapsed element) over n_dofs dofs, with
// symmetric positive semidefinite element matrices (B^T B) plus a diagonal on every dof
// so the assembled matrix is positive definite.
struct RandomElements {
  Index n_dofs = 0;
  std::vector<ElementEntries> entries;
  std::vector<bool> active;
  RandomElements(Index n, int n_elements, unsigned seed) : n_dofs(n) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<Index> dof(0, n - 1);
    std::uniform_int_distribution<int> size(2, 6);
    std::uniform_real_distribution<double> coef(0.5, 1.5);
    for (int e = 0; e < n_elements; ++e) {
      ElementEntries en;
      const int m = size(rng);
      for (int a = 0; a < m; ++a) {
        en.dofs.push_back(a == m - 1 && m > 3 ? en.dofs[0] : dof(rng));  // some dofs twice
        en.coefs.push_back(coef(rng));
        en.local.push_back(a);
      }
      entries.push_back(en);
    }
    for (Index d = 0; d < n; ++d) {  // a diagonal element on every dof
      ElementEntries en;
      en.dofs = {d};
      en.coefs = {1.0};
      en.local = {0};
      entries.push_back(en);
    }
    active.assign(static_cast<std::size_t>(n), true);
    for (Index d = 0; d < n; d += 7) active[static_cast<std::size_t>(d)] = false;  // held dofs
  }
  // Element e's matrix for value set `set` (exactly symmetric).
  Eigen::MatrixXd k(std::size_t e, int set) const {
    const int m = static_cast<int>(entries[e].dofs.size());
    Eigen::MatrixXd b(m, m);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) b(i, j) = std::sin(1.0 + i + 2.0 * j + 0.1 * e + 0.7 * set);
    Eigen::MatrixXd k = b.transpose() * b;
    k = 0.5 * (k + k.transpose()).eval();
    if (m == 1) k(0, 0) = 4.0 + set;
    return k;
  }
  void assemble(PatternAssembler& pa, int set) const {
    pa.set_zero();
    for (std::size_t e = 0; e < entries.size(); ++e) {
      const Eigen::MatrixXd ke = k(e, set);
      pa.add_element(static_cast<Index>(e), ke.data(), static_cast<int>(ke.rows()));
    }
  }
  // The dense matrix of the active unknowns (natural order).
  Eigen::MatrixXd dense(const PatternAssembler& pa, int set) const {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(pa.n_active(), pa.n_active());
    for (std::size_t e = 0; e < entries.size(); ++e) {
      const Eigen::MatrixXd ke = k(e, set);
      const ElementEntries& en = entries[e];
      for (std::size_t a = 0; a < en.dofs.size(); ++a)
        for (std::size_t b = 0; b < en.dofs.size(); ++b) {
          const Index r = pa.active_index(en.dofs[a]), c = pa.active_index(en.dofs[b]);
          if (r >= 0 && c >= 0) d(r, c) += en.coefs[a] * en.coefs[b] * ke(en.local[a], en.local[b]);
        }
    }
    return d;
  }
};

// PatternAssembler::set_order lays out tril(P A P^T): entry (k, l) holds A(order[k],
// order[l]) with the same values; entries added by global dofs land in their permuted
// places; set_order({}) gives back the natural layout, values kept.
TEST(LinalgPatternOrder, PermutedLayoutHoldsThePermutedMatrixAndComesBack) {
  const RandomElements el(120, 150, kSeed);
  for (const Storage storage : {Storage::kLower, Storage::kFull}) {
    SCOPED_TRACE(storage == Storage::kLower ? "lower" : "full");
    PatternAssembler natural(el.n_dofs, el.active, el.entries, storage);
    PatternAssembler permuted(el.n_dofs, el.active, el.entries, storage);
    const int n = static_cast<int>(natural.n_active());
    std::vector<int> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::mt19937(kSeed + 1));
    el.assemble(permuted, 0);
    permuted.set_order(order);  // values carried over
    EXPECT_EQ(permuted.order(), order);
    EXPECT_EQ(permuted.generation(), 1);
    el.assemble(natural, 0);
    const Eigen::MatrixXd a = Eigen::MatrixXd(natural.matrix());
    auto expect_permuted = [&](const char* what) {
      SCOPED_TRACE(what);
      const Eigen::MatrixXd b = Eigen::MatrixXd(permuted.matrix());
      for (int k = 0; k < n; ++k)
        for (int l = 0; l < n; ++l) {
          const int r = order[static_cast<std::size_t>(k)], c = order[static_cast<std::size_t>(l)];
          // The lower storage keeps each entry once, in the lower triangle of its own layout.
          const double want = storage == Storage::kFull ? a(r, c) : (k >= l ? (r >= c ? a(r, c) : a(c, r)) : 0.0);
          ASSERT_EQ(b(k, l), want) << k << ", " << l;
        }
    };
    expect_permuted("values carried over");
    el.assemble(permuted, 0);
    expect_permuted("assembled in the permuted layout");
    // An entry outside the elements' pattern, by global dofs (both triangles, as a symmetric
    // caller adds it): kept aside, then merged.
    Index i = -1, j = -1;
    for (Index d = 0; d < el.n_dofs && j < 0; ++d)
      if (el.active[static_cast<std::size_t>(d)]) (i < 0 ? i : j) = d;
    for (PatternAssembler* pa : {&natural, &permuted}) {
      for (int t = 0; t < 2; ++t) {  // twice: the first may grow the pattern
        el.assemble(*pa, 0);
        pa->add(i, j + 50, 0.25);
        pa->add(j + 50, i, 0.25);
        // A symmetric block by global dofs (as contact adds it): a fixed dof (-1) skipped,
        // an entry outside the pattern kept aside, the rest in place, in either layout.
        const std::vector<Index> blk{j, -1, j + 50, i};
        const double vals[16] = {2.0, 9.0, 0.5, 0.125, 9.0, 9.0, 9.0, 9.0, 0.5, 9.0, 3.0, -0.75, 0.125, 9.0, -0.75, 4.0};
        pa->add_block(blk, blk, vals, 4);
        pa->flush();
      }
    }
    const Eigen::MatrixXd a2 = Eigen::MatrixXd(natural.matrix());
    permuted.set_order({});
    EXPECT_TRUE(permuted.order().empty());
    EXPECT_EQ(Eigen::MatrixXd(permuted.matrix()), a2);
    EXPECT_EQ(permuted.matrix().nonZeros(), natural.matrix().nonZeros());
  }
}

// The Cholesky fed from a pattern laid out in its own fill-reducing order: CHOLMOD reads
// the assembler's matrix in place (kNatural, no copy of the values) and solves as the
// dense Cholesky of the natural matrix does, for new values of the same pattern too; the
// second factorisation of a pattern reuses the analysis and allocates nothing that stays
// (the library's memory in use and malloc's bytes in use are the same after it).
TEST(LinalgSolver, CholmodFedFromThePatternInItsOrderMatchesDenseCholesky) {
  if (!solver_available(SolverKind::kCholmod)) GTEST_SKIP() << "no SuiteSparse";
  const RandomElements el(400, 700, kSeed + 2);
  PatternAssembler pa(el.n_dofs, el.active, el.entries, Storage::kLower);
  const Index n = pa.n_active();
  // The order: CHOLMOD's analysis of the natural pattern.
  LinearSolver orderer(SolverKind::kCholmod);
  ASSERT_EQ(orderer.analyze_pattern(pa.matrix()).status, SolveReport::Status::kNotFactorized);
  const std::vector<int> order = orderer.permutation();
  ASSERT_EQ(static_cast<Index>(order.size()), n);
  EXPECT_TRUE(LinearSolver(SolverKind::kUmfpack).permutation().empty());
  pa.set_order(order);

  LinearSolver solver(SolverKind::kCholmod);
  solver.set_ordering(Ordering::kNatural);
  solver.keep_copy(false);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::MatrixXd b = Eigen::MatrixXd::NullaryExpr(n, kNumRhs, [&] { return u(rng); });
  double lib_bytes = 0.0;
  for (int set = 0; set < 3; ++set) {
    SCOPED_TRACE(fmt::format("values {}", set));
    el.assemble(pa, set);
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
    const std::size_t heap_before = mallinfo2().uordblks;
#endif
    const SolveReport& r = solver.factorize(pa.matrix());
    ASSERT_TRUE(r.ok()) << r.brief();
    EXPECT_EQ(r.reused_analysis, set > 0);
    EXPECT_EQ(r.ordering, "natural");
    EXPECT_GT(r.library_bytes, 0.0);
    if (set > 0) {
      EXPECT_EQ(r.library_bytes, lib_bytes) << "CHOLMOD holds more after a refactorisation";
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
      EXPECT_EQ(mallinfo2().uordblks, heap_before) << "a refactorisation kept memory it allocated";
#endif
    }
    lib_bytes = r.library_bytes;
    EXPECT_EQ(&solver.matrix(), &pa.matrix()) << "the solver reads the pattern's matrix, no copy";
    // In the order: y = B^-1 (P b), x = P^T y against the dense Cholesky of the natural A.
    Eigen::MatrixXd pb(n, b.cols());
    for (Index k = 0; k < n; ++k) pb.row(k) = b.row(order[static_cast<std::size_t>(k)]);
    const Eigen::MatrixXd y = solver.solve(pb);
    Eigen::MatrixXd x(n, b.cols());
    for (Index k = 0; k < n; ++k) x.row(order[static_cast<std::size_t>(k)]) = y.row(k);
    const Eigen::MatrixXd expected = el.dense(pa, set).llt().solve(b);
    EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
    // And as the default path solves the natural matrix (its own permuted copy).
    PatternAssembler nat(el.n_dofs, el.active, el.entries, Storage::kLower);
    el.assemble(nat, set);
    LinearSolver reference(SolverKind::kCholmod);
    ASSERT_TRUE(reference.factorize(nat.matrix()).ok());
    EXPECT_LT((reference.solve(b) - x).norm(), 1e-13 * x.norm());
  }
}

}  // namespace
}  // namespace sf::linalg
