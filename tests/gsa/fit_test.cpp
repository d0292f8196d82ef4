// The penalised least-squares fit on its own (gsa/fit.hpp, docs/theory/strain.md "The
// penalised least-squares fit"): exact reproduction of bicubic fields without smoothing,
// the null space of each penalty order, smoothing that acts on the deviation from the
// reference, monotone effects of the weight, iterated passes, the degrees of freedom, and
// a singular system reported rather than thrown.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "common/core/parallel.hpp"
#include "common/fe/surface_field.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "gsa/fit.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa {
namespace {

// ---- Named tolerances (what each bounds, and why). ----
// A field the fit represents exactly (bicubic per element on a flat rectangle mesh, values
// O(1)): a sparse Cholesky solve of ~100 unknowns; measured ~1e-13.
constexpr double kExactField = 1e-9;
// A penalty weight large enough to leave only its null space (weights are in physical
// units relative to a data term of 1 per point; the mesh spacing is 10).
constexpr double kHuge = 1e8;
// A field in the null space of a penalty of weight kHuge: the weight amplifies round-off
// (measured up to 4.5e-9); still five orders below the 1e-4 at which a penalised field
// is seen to move.
constexpr double kNullSpace = 1e-7;

// Physical field of three components on the plane z = 0: p(X, Y).
using Field = std::function<Vec3(double X, double Y)>;

// A 3 x 2 rectangle mesh of 10 x 10 elements over [0, 30] x [0, 20] in the plane z = 0,
// data points on a 6 x 6 grid of xi in every element, with the field's values there.
struct Problem {
  mesh::SurfaceMesh mesh = mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 30, 20, 3, 2);
  PenaltyMatrices penalties = assemble_penalties(mesh);
  std::vector<MeshLocation> at;
  std::vector<Vec2> xy;  // physical positions of the points

  Problem() {
    const fe::SurfaceField geometry(mesh, mesh.geometry());
    for (Index e = 0; e < mesh.n_elements(); ++e)
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
          const Vec2 xi((i + 0.5) / 6, (j + 0.5) / 6);
          at.push_back({e, xi});
          const Vec3 x = geometry.evaluate3(e, xi, basis::kValues).x;
          xy.emplace_back(x[0], x[1]);
        }
  }
  Index n_points() const { return static_cast<Index>(at.size()); }
  MatX values(const Field& f) const {
    MatX v(n_points(), 3);
    for (Index k = 0; k < n_points(); ++k) v.row(k) = f(xy[k][0], xy[k][1]).transpose();
    return v;
  }
  MatX zero_reference() const { return MatX::Zero(mesh.n_dofs(), 3); }
  // Largest difference between the fitted surface and `f` at points between the data
  // points (xi on a 5 x 5 grid of every element, none of them data points).
  double max_error(const MatX& parameters, const Field& f) const {
    const fe::SurfaceField fit(mesh, parameters), geometry(mesh, mesh.geometry());
    double worst = 0;
    for (Index e = 0; e < mesh.n_elements(); ++e)
      for (int j = 0; j <= 4; ++j)
        for (int i = 0; i <= 4; ++i) {
          const Vec2 xi(i / 4.0, j / 4.0);
          const Vec3 x = geometry.evaluate3(e, xi, basis::kValues).x;
          worst = std::max(worst, (fit.evaluate3(e, xi, basis::kValues).x - f(x[0], x[1])).norm());
        }
    return worst;
  }
};

// A random bicubic polynomial in (X, Y) per component, O(1) on the mesh.
Field random_bicubic(unsigned seed, int degree = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::array<std::array<Vec3, 4>, 4> c;
  for (auto& row : c) row.fill(Vec3::Zero());
  for (int i = 0; i <= degree; ++i)
    for (int j = 0; j <= degree; ++j)
      if (degree == 3 || i + j <= degree) c[i][j] = Vec3(u(rng), u(rng), u(rng));
  return [c](double X, double Y) {
    Vec3 v = Vec3::Zero();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) v += c[i][j] * std::pow(X / 30, i) * std::pow(Y / 20, j);
    return v;
  };
}

FitResult fit(const Problem& p, const MatX& values, const Penalty& penalty, const MatX& reference, int probes = 0,
              int passes = 1) {
  FitSystem system(p.mesh, p.penalties, p.at, VecX());
  system.set_values(values);
  return system.solve(penalty, reference, probes, passes);
}

TEST(GsaFit, ReproducesABicubicFieldExactlyWithoutSmoothing) {
  const Problem p;
  const Field f = random_bicubic(test::kSeed);
  const FitResult r = fit(p, p.values(f), Penalty{}, p.zero_reference());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(r.rms, kExactField);
  EXPECT_LT(r.max, kExactField);
  EXPECT_LT(p.max_error(r.parameters, f), kExactField);
  EXPECT_EQ(r.parameters.rows(), p.mesh.n_dofs());
  EXPECT_EQ(r.fitted.rows(), p.n_points());
}

// Each order leaves its null space unpenalised, however large the weight: constants for
// alpha, affine fields for beta, quadratics for gamma and for the boundary elements' third
// order, bicubic polynomials for delta.
TEST(GsaFit, EachPenaltyOrderLeavesItsNullSpaceAlone) {
  const Problem p;
  struct Case {
    const char* name;
    Penalty penalty;
    int degree;  // total degree of the polynomial it must leave alone (3: bicubic)
  };
  Penalty alpha, beta, gamma, delta, boundary;
  alpha.alpha = kHuge;
  beta.beta = kHuge;
  gamma.gamma = kHuge;
  delta.delta = kHuge;
  boundary.boundary = kHuge;  // every element of the 3 x 2 mesh is on its boundary: quadratics
  for (const Case& c : {Case{"alpha", alpha, 0}, Case{"beta", beta, 1}, Case{"gamma", gamma, 2},
                        Case{"delta", delta, 3}, Case{"boundary", boundary, 2}}) {
    SCOPED_TRACE(c.name);
    const Field f = random_bicubic(test::kSeed + 1, c.degree);
    const FitResult r = fit(p, p.values(f), c.penalty, p.zero_reference());
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_LT(p.max_error(r.parameters, f), kNullSpace);
    // One degree more is penalised: the fit moves away from the data.
    if (c.degree < 3) {
      const Field g = random_bicubic(test::kSeed + 2, c.degree + 1);
      EXPECT_GT(fit(p, p.values(g), c.penalty, p.zero_reference()).rms, 1e-4);
    }
  }
}

// The penalty acts on U - U_ref: with the reference a bicubic field q, data q + c (a
// constant, in alpha's null space) are fitted exactly even with a huge alpha, while the
// same weight with a zero reference flattens the fit.
TEST(GsaFit, SmoothingActsOnTheDeviationFromTheReference) {
  const Problem p;
  const Field q = random_bicubic(test::kSeed + 3);
  const MatX reference = fit(p, p.values(q), Penalty{}, p.zero_reference()).parameters;
  const Field shifted = [q](double X, double Y) { return Vec3(q(X, Y) + Vec3(0.5, -1.0, 2.0)); };
  Penalty alpha;
  alpha.alpha = kHuge;
  const FitResult with_ref = fit(p, p.values(shifted), alpha, reference);
  EXPECT_LT(p.max_error(with_ref.parameters, shifted), kNullSpace);
  const FitResult without = fit(p, p.values(shifted), alpha, p.zero_reference());
  EXPECT_GT(without.rms, 0.1);
}

// A larger weight fits the data less closely, the fitted field has less of the penalised
// quantity, and the effective degrees of freedom (Hutchinson, same probes) fall.
TEST(GsaFit, LargerWeightsSmoothMoreAndLeaveFewerDegreesOfFreedom) {
  const Problem p;
  const Field wave = [](double X, double Y) {
    return Vec3(std::sin(X / 4.0) * std::cos(Y / 5.0), 0.1 * X, std::cos(X / 3.0 + Y / 7.0));
  };
  const MatX values = p.values(wave);
  double last_rms = -1, last_edf = 1e300;
  for (double beta : {1e-2, 1.0, 1e2, 1e4}) {
    SCOPED_TRACE("beta " + std::to_string(beta));
    Penalty pen;
    pen.beta = beta;
    const FitResult r = fit(p, values, pen, p.zero_reference(), 12);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_GT(r.rms, last_rms);
    EXPECT_LT(r.edf, last_edf);
    EXPECT_GT(r.edf, 0.0);
    EXPECT_LT(r.edf, static_cast<double>(p.n_points()));
    last_rms = r.rms;
    last_edf = r.edf;
  }
}

// Iterated passes square the bias (I - A)^passes: the second pass stays closer to data
// that the smoother cannot follow, and a field the fit reproduces stays reproduced.
TEST(GsaFit, SecondPassReducesTheSmoothingBias) {
  const Problem p;
  const Field wave = [](double X, double Y) {
    return Vec3(std::sin(X / 4.0), std::cos(Y / 3.0), std::sin((X + Y) / 5.0));
  };
  Penalty pen;
  pen.delta = 1e5;
  const FitResult one = fit(p, p.values(wave), pen, p.zero_reference(), 0, 1);
  const FitResult two = fit(p, p.values(wave), pen, p.zero_reference(), 0, 2);
  EXPECT_LT(two.rms, 0.9 * one.rms);
  const Field q = random_bicubic(test::kSeed + 4);
  EXPECT_LT(p.max_error(fit(p, p.values(q), pen, p.zero_reference(), 0, 2).parameters, q), kExactField);
}

// Points with weight 0 take no part (their values may be NaN); a pair of penalties gives
// what two single solves give.
TEST(GsaFit, ZeroWeightsAndPairsOfPenalties) {
  const Problem p;
  const Field q = random_bicubic(test::kSeed + 5);
  MatX values = p.values(q);
  VecX w = VecX::Ones(p.n_points());
  for (Index k = 0; k < p.n_points(); k += 7) {
    w[k] = 0;
    values.row(k).setConstant(std::nan(""));
  }
  FitSystem system(p.mesh, p.penalties, p.at, w);
  system.set_values(values);
  const FitResult r = system.solve(Penalty{}, p.zero_reference());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(p.max_error(r.parameters, q), kExactField);
  Penalty a, b;
  a.gamma = 10;
  b.delta = 1e3;
  const std::array<FitResult, 2> pair = system.solve_pair({a, b}, p.zero_reference());
  const FitResult sa = system.solve(a, p.zero_reference()), sb = system.solve(b, p.zero_reference());
  EXPECT_LT((pair[0].parameters - sa.parameters).cwiseAbs().maxCoeff(), kExactField);
  EXPECT_LT((pair[1].parameters - sb.parameters).cwiseAbs().maxCoeff(), kExactField);
}

// The fits' factorisations are CHOLMOD's supernodal ones, through the serial OpenBLAS,
// which gives wrong numbers when two threads call it at once: a pair on two threads
// must be the same bits as the same fits one at a time, pair after pair (the two
// factorisations take turns; everything else runs side by side).
TEST(GsaFit, PairsOnTwoThreadsAreTheSameBitsAsOneAtATime) {
  const Problem p;
  const MatX values = p.values(random_bicubic(test::kSeed + 6));
  FitSystem together(p.mesh, p.penalties, p.at, VecX()), alone(p.mesh, p.penalties, p.at, VecX());
  together.set_values(values);
  alone.set_values(values);
  struct TwoThreads {
    TwoThreads() { set_default_threads(2); }
    ~TwoThreads() { set_default_threads(0); }
  } two;
  for (int k = 0; k < 12; ++k) {
    Penalty a, b;
    a.delta = std::pow(10.0, -2.0 + 0.5 * k);
    b.delta = 3.0 * a.delta;
    b.boundary = 10.0 * b.delta;
    const std::array<FitResult, 2> pair = together.solve_pair({a, b}, p.zero_reference(), 4, 2);
    const FitResult sa = alone.solve(a, p.zero_reference(), 4, 2), sb = alone.solve(b, p.zero_reference(), 4, 2);
    ASSERT_TRUE(pair[0].ok && pair[1].ok && sa.ok && sb.ok);
    EXPECT_TRUE(pair[0].parameters == sa.parameters) << "pair " << k << ", first";
    EXPECT_TRUE(pair[1].parameters == sb.parameters) << "pair " << k << ", second";
    EXPECT_EQ(pair[0].edf, sa.edf) << "pair " << k;
    EXPECT_EQ(pair[1].edf, sb.edf) << "pair " << k;
  }
}

// The smoothing residuals of other data (noise probes, many columns) are the data less
// the fit of them with a zero reference, to the bit, and at chosen points the same bits
// as at all (one kernel does Phi x parameters for whole and gathered rows, for any
// column count; gsa-speed6's kernels keep Eigen's order of operations).
TEST(GsaFit, SmoothingResidualsAreTheFitsResidualsToTheBitAtAllOrChosenPoints) {
  const Problem p;
  std::mt19937 rng(test::kSeed + 7);
  std::normal_distribution<double> normal(0.0, 1.0);
  MatX probes(p.n_points(), 11);  // one group of 8 columns and one of 3
  for (Index k = 0; k < probes.size(); ++k) probes.data()[k] = normal(rng);
  FitSystem system(p.mesh, p.penalties, p.at, VecX());
  Penalty pen;
  pen.delta = 30.0;
  pen.boundary = 300.0;
  for (const int passes : {1, 2}) {
    const std::optional<MatX> whole = system.smoothing_residual(probes, pen, passes);
    ASSERT_TRUE(whole);
    system.set_values(probes);
    const FitResult f = system.solve(pen, MatX::Zero(p.mesh.n_dofs(), probes.cols()), 0, passes);
    ASSERT_TRUE(f.ok) << f.message;
    EXPECT_TRUE(*whole == MatX(probes - f.fitted)) << passes << " passes";
    const std::vector<Index> rows = {5, 0, 77, p.n_points() - 1, 5};
    const std::optional<MatX> some =
        system.smoothing_residual(probes, system.weighted_values(probes), pen, passes, 1, &rows);
    ASSERT_TRUE(some);
    for (std::size_t i = 0; i < rows.size(); ++i)
      EXPECT_TRUE(some->row(static_cast<Index>(i)) == whole->row(rows[i])) << "row " << rows[i];
  }
}

// Too few points for the mesh and no smoothing: the fit reports a singular system (a
// numerical outcome, not an exception) and says what to do.
TEST(GsaFit, SingularSystemIsReportedNotThrown) {
  const Problem p;
  const std::vector<MeshLocation> few = {{0, Vec2(0.5, 0.5)}, {1, Vec2(0.5, 0.5)}};
  FitSystem system(p.mesh, p.penalties, few, VecX());
  system.set_values(MatX::Ones(2, 3));
  const FitResult r = system.solve(Penalty{}, p.zero_reference());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("singular"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace sf::gsa
