// Accuracy of `gsa analyse` on the analytic deformations of gsa/synthetic.hpp
// (21 x 21 marks at 5 mm): exact answers where the method must be exact, bounded
// errors where the fit approximates a curved surface, the surface method against
// the classical triangles on noisy grids, and the triangles method itself.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "gsa/accuracy.hpp"
#include "gsa/analysis.hpp"
#include "gsa/synthetic.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa {
namespace {

// ---- Named tolerances of the gsa accuracy tests (what each bounds, and why). ----
namespace tol {
// Strains that the method reproduces exactly in exact arithmetic (rigid motion,
// homogeneous stretch and shear of a flat sheet: the bicubic surfaces represent
// the maps exactly). Measured ~1e-14; 1e-9 leaves room for solver round-off.
inline constexpr double kExactStrain = 1e-9;
// Fit residuals (mm) of a surface the mesh represents exactly.
inline constexpr double kExactResidual = 1e-9;
// Unit direction vectors compared by 1 - |a.b| when the strain is exact.
inline constexpr double kExactDirection = 1e-9;
// Noise-free RMS Green-strain error at interior marks (border 1) on curved cases;
// measured 1.2e-5 (cylinder), 9.7e-6 (dome), 8.5e-5 (wavy): the brief's bounds.
inline constexpr double kCylinderRms = 2e-4;
inline constexpr double kDomeRms = 1e-4;
inline constexpr double kWavyRms = 2e-4;
// Cylinder: the computed major direction against the exact one (1 - |a.b|,
// interior marks). Measured ~1e-9; the directions are well separated (1.08 vs 0.97).
inline constexpr double kCylinderDirection = 1e-5;
// Trellis (fibres 0, 90), noise-free: RMS shear-angle error (degrees) and the
// deviation of the fibre stretch from 1 (inextensible fibres), interior marks.
// Measured 2e-4 degrees and 1.1e-6.
inline constexpr double kTrellisShearDeg = 0.05;
inline constexpr double kTrellisFibreStretch = 1e-3;
// Noisy grids (0.01 mm, seeds 1..2): mean RMS error of the surface method over that
// of the triangles method must stay below these. Measured (gsa_accuracy_bench 2):
// rigid 0.42, stretch 0.41 (flat); per seed 1, 2: dome 0.63, 0.62; cylinder 0.78,
// 0.85 (the brief quoted 0.71-0.84 for the curved cases).
inline constexpr double kNoisyFlatRatio = 0.6;
inline constexpr double kNoisyCurvedRatio = 0.95;
// Digitisation noise (mm) of the noisy comparisons.
inline constexpr double kNoise = 0.01;
// Dome with 10 % of the deformed marks missing, or with 2 outliers, noise-free:
// RMS error at the remaining interior marks. Measured 1.9e-5 (missing), 1.0e-5
// (outliers, once fixed); the complete dome gives 9.7e-6.
inline constexpr double kDomeDegradedRms = 2e-4;
// Rigid motion of a CURVED part (the dome shape moved rigidly): what it should give
// (zero strain up to solver round-off and the projection tolerance) and the bound
// the current library meets (measured max 6.4e-4; see the DISABLED_ test).
inline constexpr double kCurvedRigidStrain = 1e-6;
inline constexpr double kCurvedRigidStrainNow = 1e-3;
// Outliers removed: the RMS error of the remaining marks may exceed that of the
// same grid without outliers by this factor (measured 1.00 on dome and cylinder).
inline constexpr double kOutlierRemovedRel = 1.05;
}  // namespace tol

struct CaseRun {
  GridData grid;
  std::vector<ExactStrain> exact;
  AnalysisResult result;
};

CaseRun run_case(const std::string& name, const SyntheticGridOptions& go = {}, AnalyseOptions o = {}) {
  CaseRun r;
  r.grid = make_synthetic_grid(synthetic_case(name), go, &r.exact);
  if (name == "trellis" && o.fibre_angles.empty()) o.fibre_angles = {0, 90};
  r.result = analyse(r.grid, o);
  return r;
}

// Largest |f(p)| over the marks with a strain, with the id where it occurs.
template <class F>
std::pair<double, std::string> worst(const CaseRun& r, F&& f) {
  double w = -1.0;
  std::string id = "(none)";
  for (Index p = 0; p < r.grid.n_points(); ++p) {
    const auto& s = r.result.points[p].strain;
    if (!s) continue;
    const double v = std::abs(f(p, *s));
    if (!(v <= w)) {  // NaN counts as worst
      w = std::isnan(v) ? std::numeric_limits<double>::infinity() : v;
      id = r.grid.ids[p];
    }
  }
  return {w, id};
}

Index count_status(const AnalysisResult& r, const std::string& status) {
  return std::count_if(r.points.begin(), r.points.end(), [&](const PointResult& p) { return p.status == status; });
}

std::string describe(const StrainError& e) {
  std::ostringstream os;
  os << "rms " << e.rms() << " (E1 " << e.rms_e1 << ", E2 " << e.rms_e2 << "), max " << e.max_abs << ", n " << e.n
     << ", missing " << e.n_missing;
  return os.str();
}

// The exact maps' rotation (gsa/synthetic.cpp: 0.7 rad about (1, 2, 3)).
Mat3 synthetic_rotation() { return Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix(); }

// ---------------------------------------------------------------- exact cases

TEST(GsaAccuracy, RigidMotionGivesZeroStrainAtEveryMark) {
  const CaseRun r = run_case("rigid");
  ASSERT_EQ(count_status(r.result, kStatusOk), r.grid.n_points());
  const auto [e1, id1] = worst(r, [](Index, const SurfaceStrain& s) { return s.green(0); });
  const auto [e2, id2] = worst(r, [](Index, const SurfaceStrain& s) { return s.green(1); });
  const auto [l1, idl1] = worst(r, [](Index, const SurfaceStrain& s) { return s.lambda1 - 1.0; });
  const auto [l2, idl2] = worst(r, [](Index, const SurfaceStrain& s) { return s.lambda2 - 1.0; });
  const auto [th, idt] = worst(r, [](Index, const SurfaceStrain& s) { return s.thickness_change_pct(); });
  EXPECT_LT(e1, tol::kExactStrain) << "|E1| at " << id1;
  EXPECT_LT(e2, tol::kExactStrain) << "|E2| at " << id2;
  EXPECT_LT(l1, tol::kExactStrain) << "|lambda1 - 1| at " << idl1;
  EXPECT_LT(l2, tol::kExactStrain) << "|lambda2 - 1| at " << idl2;
  EXPECT_LT(th, 100 * tol::kExactStrain) << "|thickness change %| at " << idt;
  EXPECT_LT(r.result.rms_undeformed, tol::kExactResidual);
  EXPECT_LT(r.result.rms_deformed, tol::kExactResidual);
  // The deformed normal is the rotated flat normal (+-Z rotated).
  const Vec3 n = synthetic_rotation() * Vec3::UnitZ();
  const auto [dn, idn] = worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.normal_deformed.dot(n)); });
  EXPECT_LT(dn, tol::kExactDirection) << "deformed normal at " << idn;
}

TEST(GsaAccuracy, HomogeneousStretchIsExactWithDirections) {
  const CaseRun r = run_case("stretch");
  const StrainError e = strain_error(r.grid, r.result, r.exact, /*border=*/0);
  EXPECT_EQ(e.n, r.grid.n_points());
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.max_abs, tol::kExactStrain) << describe(e);
  // Major stretch 1.2 along X, then rotated: dir1 (deformed) = R e_x, dir1 (undeformed) = e_x.
  const Vec3 d1 = synthetic_rotation() * Vec3::UnitX();
  const auto [dd, idd] = worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
  const auto [du, idu] = worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_undeformed.dot(Vec3::UnitX())); });
  EXPECT_LT(dd, tol::kExactDirection) << "deformed major direction at " << idd;
  EXPECT_LT(du, tol::kExactDirection) << "undeformed major direction at " << idu;
  const auto [th, idt] = worst(r, [](Index, const SurfaceStrain& s) {
    return s.thickness_change_pct() - 100.0 * (1.0 / (1.2 * 0.9) - 1.0);
  });
  EXPECT_LT(th, 100 * tol::kExactStrain) << "thickness change at " << idt;
}

TEST(GsaAccuracy, SimpleShearIsExactWithDirections) {
  const CaseRun r = run_case("shear");
  const StrainError e = strain_error(r.grid, r.result, r.exact, /*border=*/0);
  EXPECT_EQ(e.n, r.grid.n_points());
  EXPECT_LT(e.max_abs, tol::kExactStrain) << describe(e);
  // x = X + 0.3 Y: the major direction on the deformed sheet is the major
  // eigenvector of b = F F^T, with F = [[1, 0.3], [0, 1]].
  Mat2 F;
  F << 1.0, 0.3, 0.0, 1.0;
  Eigen::SelfAdjointEigenSolver<Mat2> es(F * F.transpose());
  const Vec3 d1(es.eigenvectors()(0, 1), es.eigenvectors()(1, 1), 0.0);
  const auto [dd, idd] = worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
  EXPECT_LT(dd, tol::kExactDirection) << "deformed major direction at " << idd;
  // The sheet stays in its plane: the surface strain conserves the area ratio
  // lambda1 lambda2 = det F = 1.
  const auto [area, ida] = worst(r, [](Index, const SurfaceStrain& s) { return s.lambda1 * s.lambda2 - 1.0; });
  EXPECT_LT(area, tol::kExactStrain) << "area ratio at " << ida;
}

TEST(GsaAccuracy, PrincipalStrainsAreOrdered) {
  for (const std::string name : {"shear", "dome", "wavy"}) {
    SCOPED_TRACE(name);
    const CaseRun r = run_case(name);
    const auto [bad, id] = worst(r, [](Index, const SurfaceStrain& s) {
      return s.lambda1 >= s.lambda2 && s.green(0) >= s.green(1) ? 0.0 : 1.0;
    });
    EXPECT_EQ(bad, 0.0) << "lambda1 < lambda2 at " << id;
  }
}

// ---------------------------------------------------------------- curved, noise-free

TEST(GsaAccuracy, CylinderNoiseFree) {
  const CaseRun r = run_case("cylinder");
  const StrainError e = strain_error(r.grid, r.result, r.exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_GT(e.n, 300);
  EXPECT_LT(e.rms(), tol::kCylinderRms) << describe(e);
  // Major stretch 1.08 along X, bent about the Y axis: on the deformed surface the
  // major direction is the circle's tangent (cos(s/R), 0, sin(s/R)), s = 1.08 X.
  double w = 0;
  std::string where;
  for (Index p = 0; p < r.grid.n_points(); ++p) {
    const auto& s = r.result.points[p].strain;
    if (!s || r.grid.i[p] == 0 || r.grid.j[p] == 0 || r.grid.i[p] == 20 || r.grid.j[p] == 20) continue;
    const double t = 1.08 * r.grid.undeformed(p, 0) / 60.0;
    const double d = 1.0 - std::abs(s->dir1_deformed.dot(Vec3(std::cos(t), 0, std::sin(t))));
    if (d > w) w = d, where = r.grid.ids[p];
  }
  EXPECT_LT(w, tol::kCylinderDirection) << "major direction at " << where;
}

TEST(GsaAccuracy, DomeNoiseFree) {
  const CaseRun r = run_case("dome");
  const StrainError e = strain_error(r.grid, r.result, r.exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms(), tol::kDomeRms) << describe(e);
}

TEST(GsaAccuracy, WavyNoiseFree) {
  const CaseRun r = run_case("wavy");
  const StrainError e = strain_error(r.grid, r.result, r.exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms(), tol::kWavyRms) << describe(e);
}

TEST(GsaAccuracy, TrellisShearAngleAndInextensibleFibres) {
  const CaseRun r = run_case("trellis");
  const StrainError e = strain_error(r.grid, r.result, r.exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms_shear_deg, tol::kTrellisShearDeg) << describe(e);
  Index n = 0;
  double w = 0;
  std::string where;
  for (Index p = 0; p < r.grid.n_points(); ++p) {
    const PointResult& pr = r.result.points[p];
    if (!pr.strain || r.grid.i[p] == 0 || r.grid.j[p] == 0 || r.grid.i[p] == 20 || r.grid.j[p] == 20) continue;
    ASSERT_EQ(pr.fibres.size(), 2u) << r.grid.ids[p];
    ASSERT_TRUE(std::isfinite(pr.shear_angle_deg)) << r.grid.ids[p];
    for (const FibreResult& f : pr.fibres) {
      const double d = std::abs(f.stretch - 1.0);
      if (!(d <= w)) w = d, where = r.grid.ids[p];
    }
    ++n;
  }
  EXPECT_GT(n, 300);
  EXPECT_LT(w, tol::kTrellisFibreStretch) << "|fibre stretch - 1| at " << where;
  // The exact shear grows from 0 to 34.4 degrees: the computed range must follow.
  double lo = 1e9, hi = -1e9;
  for (const PointResult& pr : r.result.points)
    if (pr.strain) lo = std::min(lo, pr.shear_angle_deg), hi = std::max(hi, pr.shear_angle_deg);
  EXPECT_NEAR(lo, 0.0, 1.0);
  EXPECT_NEAR(hi, 34.4, 1.0);
}

// The dome shape (noise-free) as the UNDEFORMED part, moved rigidly.
GridData curved_part_moved(bool rotate) {
  GridData g = make_synthetic_grid(synthetic_case("dome"), {});
  const Mat3 R = rotate ? synthetic_rotation() : Mat3::Identity();
  g.undeformed = g.deformed;
  for (Index p = 0; p < g.n_points(); ++p)
    g.deformed.row(p) = (R * g.undeformed.row(p).transpose() + Vec3(10, -5, 3)).transpose();
  return g;
}

TEST(GsaAccuracy, RigidMotionOfCurvedPartStrainIsBounded) {
  // Regression guard for the current behaviour (see the DISABLED_ test below for
  // the intended one): measured max |E| 8.7e-5 (translation), 6.4e-4 (rotation).
  for (const bool rotate : {false, true}) {
    SCOPED_TRACE(rotate ? "rotation + translation" : "translation");
    const GridData g = curved_part_moved(rotate);
    const AnalysisResult res = analyse(g, {});
    const std::vector<ExactStrain> zero(static_cast<std::size_t>(g.n_points()));
    const StrainError e = strain_error(g, res, zero);
    EXPECT_EQ(e.n_missing, 0);
    EXPECT_LT(e.max_abs, tol::kCurvedRigidStrainNow) << describe(e);
  }
}

// LIBRARY BUG (reported to the lead): a rigid motion of a CURVED undeformed part
// gives spurious strain (strain.hpp promises m = M under rigid motion). Measured,
// dome shape, noise-free, automatic smoothing: translation only max |E| 8.7e-5
// (rms 2.8e-5); rotation 0.7 rad + translation max 6.4e-4 (rms 1.5e-4). Causes seen
// in gsa/analysis.cpp: (1) the undeformed fit/projection loop updates the marks' xi
// AFTER the last undeformed fit (the loop never reaches its 1e-7 tolerance on the
// dome, even in 50 iterations), and the deformed fit then uses xi the undeformed
// surface was not fitted at -- with --gamma 0 (no smoothing at all) a translation
// still gives max |E| 5.7e-5; (2) the deformed fit smooths the displacement
// (R - I) X, whose third derivatives are not zero on a curved X, so a rotation is
// penalised like a deformation. Expected: zero strain to round-off-like accuracy.
TEST(GsaAccuracy, DISABLED_RigidMotionOfCurvedPartGivesZeroStrain) {
  for (const bool rotate : {false, true}) {
    SCOPED_TRACE(rotate ? "rotation + translation" : "translation");
    const GridData g = curved_part_moved(rotate);
    const AnalysisResult res = analyse(g, {});
    const std::vector<ExactStrain> zero(static_cast<std::size_t>(g.n_points()));
    const StrainError e = strain_error(g, res, zero, /*border=*/0);
    EXPECT_EQ(e.n_missing, 0);
    EXPECT_LT(e.max_abs, tol::kCurvedRigidStrain) << describe(e);
  }
}

// ---------------------------------------------------------------- noisy: surface vs triangles

// Mean (over seeds 1..2) RMS error of the surface and the triangles method.
std::pair<double, double> noisy_errors(const std::string& name) {
  double s = 0, t = 0;
  for (unsigned seed = 1; seed <= 2; ++seed) {
    SyntheticGridOptions go;
    go.noise = tol::kNoise;
    go.seed = seed;
    std::vector<ExactStrain> exact;
    const GridData g = make_synthetic_grid(synthetic_case(name), go, &exact);
    AnalyseOptions o;
    const AnalysisResult rs = analyse(g, o);
    o.method = Method::kTriangles;
    const AnalysisResult rt = analyse(g, o);
    const StrainError es = strain_error(g, rs, exact), et = strain_error(g, rt, exact);
    EXPECT_EQ(es.n_missing, 0) << name << " seed " << seed << " surface";
    EXPECT_EQ(et.n_missing, 0) << name << " seed " << seed << " triangles";
    s += es.rms();
    t += et.rms();
  }
  return {s / 2, t / 2};
}

class NoisyFlat : public ::testing::TestWithParam<std::string> {};
TEST_P(NoisyFlat, SurfaceBeatsTriangles) {
  const auto [s, t] = noisy_errors(GetParam());
  EXPECT_LT(s, tol::kNoisyFlatRatio * t) << "surface rms " << s << ", triangles rms " << t << ", ratio " << s / t;
}
INSTANTIATE_TEST_SUITE_P(GsaAccuracy, NoisyFlat, ::testing::Values("rigid", "stretch"));

class NoisyCurved : public ::testing::TestWithParam<std::string> {};
TEST_P(NoisyCurved, SurfaceBeatsTriangles) {
  const auto [s, t] = noisy_errors(GetParam());
  EXPECT_LT(s, tol::kNoisyCurvedRatio * t) << "surface rms " << s << ", triangles rms " << t << ", ratio " << s / t;
}
INSTANTIATE_TEST_SUITE_P(GsaAccuracy, NoisyCurved, ::testing::Values("dome", "cylinder"));

// ---------------------------------------------------------------- triangles method

TEST(GsaTriangles, HomogeneousStretchIsExactOnGridTriangles) {
  AnalyseOptions o;
  o.method = Method::kTriangles;
  const CaseRun r = run_case("stretch", {}, o);
  EXPECT_EQ(r.result.method, Method::kTriangles);
  EXPECT_EQ(r.result.n_triangles, 4 * 20 * 20);  // four triangles per complete grid cell
  const StrainError e = strain_error(r.grid, r.result, r.exact, /*border=*/0);
  EXPECT_EQ(e.n, r.grid.n_points());
  EXPECT_LT(e.max_abs, tol::kExactStrain) << describe(e);
  const Vec3 d1 = synthetic_rotation() * Vec3::UnitX();
  const auto [dd, idd] = worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
  EXPECT_LT(dd, tol::kExactDirection) << "deformed major direction at " << idd;
}

TEST(GsaTriangles, HomogeneousStretchIsExactOnDelaunayTrianglesWithoutIJ) {
  std::vector<ExactStrain> exact;
  const GridData with_ij = make_synthetic_grid(synthetic_case("stretch"), {}, &exact);
  GridData g = with_ij;
  g.has_ij = false;
  g.i.clear();
  g.j.clear();
  AnalyseOptions o;
  o.method = Method::kTriangles;
  const AnalysisResult res = analyse(g, o);
  // A Delaunay triangulation of the 21 x 21 square lattice: two triangles a cell.
  EXPECT_EQ(res.n_triangles, 2 * 20 * 20);
  EXPECT_EQ(count_status(res, kStatusOk), g.n_points());
  const StrainError e = strain_error(with_ij, res, exact, /*border=*/0);  // with_ij only locates the marks
  EXPECT_EQ(e.n, g.n_points());
  EXPECT_LT(e.max_abs, tol::kExactStrain) << describe(e);
}

TEST(GsaTriangles, RigidMotionGivesZeroStrain) {
  AnalyseOptions o;
  o.method = Method::kTriangles;
  const CaseRun r = run_case("rigid", {}, o);
  const StrainError e = strain_error(r.grid, r.result, r.exact, /*border=*/0);
  EXPECT_EQ(e.n, r.grid.n_points());
  EXPECT_LT(e.max_abs, tol::kExactStrain) << describe(e);
}

TEST(GsaTriangles, MissingDeformedMarksAreFlaggedAndTheRestStayExact) {
  SyntheticGridOptions go;
  go.missing_deformed = 0.1;
  AnalyseOptions o;
  o.method = Method::kTriangles;
  const CaseRun r = run_case("stretch", go, o);
  Index missing = 0;
  for (Index p = 0; p < r.grid.n_points(); ++p) {
    const PointResult& pr = r.result.points[p];
    if (!r.grid.has_deformed(p)) {
      ++missing;
      EXPECT_EQ(pr.status, kStatusMissingDeformed) << r.grid.ids[p];
      EXPECT_FALSE(pr.strain) << r.grid.ids[p];
    } else if (pr.status == kStatusOk) {
      ASSERT_TRUE(pr.strain);
      EXPECT_NEAR(pr.strain->lambda1, 1.2, tol::kExactStrain) << r.grid.ids[p];
      EXPECT_NEAR(pr.strain->lambda2, 0.9, tol::kExactStrain) << r.grid.ids[p];
    } else {
      // A mark whose neighbours are all missing has no triangle; nothing else is allowed.
      EXPECT_EQ(pr.status, kStatusNoTriangle) << r.grid.ids[p];
    }
  }
  EXPECT_GT(missing, 20);
  EXPECT_LT(missing, 70);
}

// ---------------------------------------------------------------- missing marks and outliers

TEST(GsaMissing, MissingDeformedMarksHaveNoStrainAndOthersAreOk) {
  SyntheticGridOptions go;
  go.missing_deformed = 0.1;
  const CaseRun r = run_case("dome", go);
  Index missing = 0;
  for (Index p = 0; p < r.grid.n_points(); ++p) {
    const PointResult& pr = r.result.points[p];
    if (!r.grid.has_deformed(p)) {
      ++missing;
      EXPECT_EQ(pr.status, kStatusMissingDeformed) << r.grid.ids[p];
      EXPECT_FALSE(pr.strain) << r.grid.ids[p];
      EXPECT_TRUE(std::isnan(pr.residual)) << r.grid.ids[p];
      // It still took part in the undeformed fit, so it has a place on the mesh.
      EXPECT_GE(pr.element, 0) << r.grid.ids[p];
    } else {
      EXPECT_EQ(pr.status, kStatusOk) << r.grid.ids[p];
      EXPECT_TRUE(pr.strain) << r.grid.ids[p];
    }
  }
  EXPECT_GT(missing, 20);
  EXPECT_LT(missing, 70);
  const StrainError e = strain_error(r.grid, r.result, r.exact);
  EXPECT_LT(e.rms(), tol::kDomeDegradedRms) << describe(e);
}

TEST(GsaMissing, MissingUndeformedMarkIsFlaggedAndTakesNoPart) {
  std::vector<ExactStrain> exact;
  GridData g = make_synthetic_grid(synthetic_case("dome"), {}, &exact);
  const Index p = 5 * 21 + 7;
  g.undeformed.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
  for (const Method m : {Method::kSurface, Method::kTriangles}) {
    SCOPED_TRACE(m == Method::kSurface ? "surface" : "triangles");
    AnalyseOptions o;
    o.method = m;
    const AnalysisResult res = analyse(g, o);
    EXPECT_EQ(res.points[p].status, kStatusMissingUndeformed);
    EXPECT_FALSE(res.points[p].strain);
    EXPECT_EQ(res.points[p].element, -1);
    EXPECT_EQ(count_status(res, kStatusOk), g.n_points() - 1);
  }
}

// make_synthetic_grid moves marks (k * 7919 + n / 3) % n, k = 0, 1, by 2 mm in z.
std::vector<Index> moved_marks(Index n) { return {(n / 3) % n, (7919 + n / 3) % n}; }

// Moved marks at least one row inside the grid edge (those strain_error counts).
Index interior_moved_marks(const GridData& g) {
  long imax = 0, jmax = 0;
  for (Index p = 0; p < g.n_points(); ++p) imax = std::max(imax, g.i[p]), jmax = std::max(jmax, g.j[p]);
  Index k = 0;
  for (Index p : moved_marks(g.n_points())) k += g.i[p] > 0 && g.j[p] > 0 && g.i[p] < imax && g.j[p] < jmax;
  return k;
}

// Checks that exactly the moved marks are flagged outlier_deformed.
void expect_only_moved_marks_flagged(const GridData& g, const AnalysisResult& res) {
  const std::vector<Index> moved = moved_marks(g.n_points());
  for (Index p = 0; p < g.n_points(); ++p) {
    if (std::find(moved.begin(), moved.end(), p) != moved.end()) {
      EXPECT_EQ(res.points[p].status, kStatusOutlierDeformed) << g.ids[p];
      EXPECT_FALSE(res.points[p].strain) << g.ids[p];
    } else {
      EXPECT_EQ(res.points[p].status, kStatusOk) << g.ids[p] << " is not an outlier";
    }
  }
}

class NoisyOutliers : public ::testing::TestWithParam<std::string> {};
TEST_P(NoisyOutliers, AreFlaggedAndTheRestStayAsAccurate) {
  SyntheticGridOptions go;
  go.noise = tol::kNoise;
  go.seed = 1;
  std::vector<ExactStrain> exact;
  const GridData clean = make_synthetic_grid(synthetic_case(GetParam()), go, &exact);
  go.outliers = 2;
  const GridData g = make_synthetic_grid(synthetic_case(GetParam()), go);
  const AnalysisResult res = analyse(g, {});
  expect_only_moved_marks_flagged(g, res);
  const StrainError e = strain_error(g, res, exact), e0 = strain_error(clean, analyse(clean, {}), exact);
  EXPECT_EQ(e.n_missing, interior_moved_marks(g));
  EXPECT_LT(e.rms(), tol::kOutlierRemovedRel * e0.rms()) << "with outliers: " << describe(e)
                                                         << "; without: " << describe(e0);
}
INSTANTIATE_TEST_SUITE_P(GsaMissing, NoisyOutliers, ::testing::Values("dome", "cylinder"));

// LIBRARY BUG (reported to the lead): on a noise-free grid, good marks next to an
// outlier are flagged too. Input: make_synthetic_grid(dome (or stretch, cylinder),
// {.outliers = 2}) -- marks P7_0 and P6_2 moved 2 mm. Result: P6_0, P7_2 and P8_0
// (their neighbours) are also "outlier_deformed" and lose their strain. Cause
// (gsa/analysis.cpp, deformed fit): all marks above max(6 sigma, 0.02 d) are dropped
// in ONE pass after a fit that the outliers themselves pulled; with the noise
// estimate ~0 the threshold is 0.1 mm and the 2 mm outlier drags its neighbours'
// residuals above it. Expected: only the two moved marks flagged (e.g. drop the
// worst mark, refit, repeat; or readmit marks whose residual is small after the refit).
TEST(GsaMissing, DISABLED_NoiseFreeOutliersAreTheOnlyMarksFlagged) {
  SyntheticGridOptions go;
  go.outliers = 2;
  std::vector<ExactStrain> exact;
  const GridData g = make_synthetic_grid(synthetic_case("dome"), go, &exact);
  const AnalysisResult res = analyse(g, {});
  expect_only_moved_marks_flagged(g, res);
  const StrainError e = strain_error(g, res, exact);
  EXPECT_EQ(e.n_missing, interior_moved_marks(g));
  EXPECT_LT(e.rms(), tol::kDomeDegradedRms) << describe(e);
}

}  // namespace
}  // namespace sf::gsa
