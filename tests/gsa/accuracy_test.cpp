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
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/io/csv.hpp"
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
// Extremes of the trellis shear over all marks against the exact 0 and 34.4 degrees
// (a coarse check that the whole range is followed, border marks included).
inline constexpr double kTrellisRangeDeg = 1.0;
// Trellis principal Green strains (measured RMS 1.6e-6).
inline constexpr double kTrellisRms = 1e-4;
// Noisy grids (0.01 mm, seeds 1..2): mean RMS error of the surface method over that
// of the triangles method must stay below these. Measured (ratio of the means over
// seeds 1, 2): rigid 0.086, stretch 0.076; dome 0.184, cylinder 0.219, trellis
// 0.160, wavy 0.258 (the target, 0.3, is the bound).
inline constexpr double kNoisyFlatRatio = 0.15;
inline constexpr double kNoisyCurvedRatio = 0.3;
// Digitisation noise (mm) of the noisy comparisons.
inline constexpr double kNoise = 0.01;
// Dome with 10 % of the deformed marks missing, or with 2 outliers, noise-free:
// RMS error at the remaining interior marks. Measured 1.9e-5 (missing), 1.0e-5
// (outliers, once fixed); the complete dome gives 9.7e-6.
inline constexpr double kDomeDegradedRms = 2e-4;
// Rigid motion of a CURVED part (the dome shape moved rigidly), noise-free, all
// marks: zero strain up to round-off (measured max 4e-14 translation, 3e-14 with a
// 0.7 rad rotation). The same noisy grid with its deformed scan moved rigidly gives
// the same strains (objectivity; measured 4e-14).
inline constexpr double kCurvedRigidStrain = 1e-9;
inline constexpr double kObjectivity = 1e-9;
// Outliers removed: the RMS error of the remaining marks may exceed that of the
// same grid without outliers by this factor (measured 1.00 on dome and cylinder).
inline constexpr double kOutlierRemovedRel = 1.05;
// Sample data in data/gsa/ (docs/usage.md, "Worked examples"): RMS error at
// interior marks against the shipped exact.csv. Noise-free samples as above;
// dome_noisy (0.01 mm noise, 5 % missing, 2 outliers) measured 1.0e-3 (E1 1.1e-3,
// E2 0.9e-3).
inline constexpr double kSampleNoisyDomeRms = 2e-3;
// Fibre mode against fibre states computed from the exact map (central differences,
// step kFibreFdStep mm: truncation ~1e-11 on these maps). Homogeneous simple shear,
// where both methods are exact: measured 3e-8 degrees and 4e-10 (surface).
inline constexpr double kFibreFdStep = 1e-5;
inline constexpr double kExactShearDeg = 1e-6;
inline constexpr double kExactFibreStretch = 1e-8;
// Surface method on the curved cases (dome, wavy), interior marks, any fibre pair:
// measured max 0.018 degrees and 2.2e-4 (wavy), 0.0025 degrees and 3e-5 (dome).
inline constexpr double kCurvedShearDeg = 0.05;
inline constexpr double kCurvedFibreStretch = 5e-4;
// Triangles method on the dome (chords instead of arcs), when the fibres are not
// mirrored: measured 6e-4 degrees and 1.2e-3 in stretch.
inline constexpr double kTrianglesCurvedShearDeg = 0.5;
inline constexpr double kTrianglesCurvedFibreStretch = 5e-3;
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

// How the analysis chose its smoothing, for failure messages.
std::string describe(const AnalysisResult& a) {
  std::ostringstream os;
  Index flagged = 0;
  for (const PointResult& p : a.points) flagged += p.flag ? 1 : 0;
  os << "noise und " << a.noise_undeformed.sigma_total() << " L " << a.noise_undeformed.effective_length()
     << ", def sc " << a.noise.sigma_correlated << " sw " << a.noise.sigma_white << ", log10 delta "
     << a.log10_delta_optimum << ", gauge " << a.gauge_length << ", relaxed " << a.relaxed_elements << ", flagged "
     << flagged;
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
  const auto [dn, idn] =
      worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.normal_deformed.dot(n)); });
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
  const auto [dd, idd] =
      worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
  const auto [du, idu] =
      worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_undeformed.dot(Vec3::UnitX())); });
  EXPECT_LT(dd, tol::kExactDirection) << "deformed major direction at " << idd;
  EXPECT_LT(du, tol::kExactDirection) << "undeformed major direction at " << idu;
  const auto [th, idt] = worst(
      r, [](Index, const SurfaceStrain& s) { return s.thickness_change_pct() - 100.0 * (1.0 / (1.2 * 0.9) - 1.0); });
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
  const auto [dd, idd] =
      worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
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
  EXPECT_LT(e.rms(), tol::kWavyRms) << describe(e) << "; " << describe(r.result);
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
  EXPECT_NEAR(lo, 0.0, tol::kTrellisRangeDeg);
  EXPECT_NEAR(hi, 34.4, tol::kTrellisRangeDeg);
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

// The deformed fit smooths the deviation from the undeformed surface moved rigidly,
// and carries each mark's undeformed residual with it (gsa/analysis.cpp): a curved
// part moved rigidly is fitted by the same surface moved rigidly.
TEST(GsaAccuracy, RigidMotionOfCurvedPartGivesZeroStrain) {
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

TEST(GsaAccuracy, RigidMotionOfTheDeformedScanLeavesStrainsUnchanged) {
  SyntheticGridOptions go;
  go.noise = tol::kNoise;
  GridData g = make_synthetic_grid(synthetic_case("wavy"), go);
  const AnalysisResult a = analyse(g, {});
  const Mat3 R = synthetic_rotation();
  for (Index p = 0; p < g.n_points(); ++p)
    g.deformed.row(p) = (R * g.deformed.row(p).transpose() + Vec3(-40, 7, 12)).transpose();
  const AnalysisResult b = analyse(g, {});
  double worst = 0.0;
  for (Index p = 0; p < g.n_points(); ++p) {
    ASSERT_EQ(a.points[p].strain.has_value(), b.points[p].strain.has_value());
    if (!a.points[p].strain) continue;
    worst = std::max({worst, std::abs(a.points[p].strain->lambda1 - b.points[p].strain->lambda1),
                      std::abs(a.points[p].strain->lambda2 - b.points[p].strain->lambda2)});
  }
  EXPECT_LT(worst, tol::kObjectivity);
}

// A round blank (the marks inside the grid's inscribed circle): the rectangle mesh
// keeps the elements holding marks, and the rim marks are fitted with their
// neighbours on one side only. Measured on the dome, 21 marks across: noise-free
// RMS 1.1e-5 inside the rim and 3.0e-5 over all marks; at 0.01 mm noise (seeds
// 1, 2) 0.157 of the classical method's error inside the rim.
TEST(GsaAccuracy, RoundBlankIsAnalysedLikeASquareOne) {
  SyntheticGridOptions go;
  go.round = true;
  std::vector<ExactStrain> exact;
  GridData g = make_synthetic_grid(synthetic_case("dome"), go, &exact);
  ASSERT_LT(g.n_points(), 21 * 21 * 0.8);  // the corners are gone
  const AnalysisResult res = analyse(g, {});
  EXPECT_LT(strain_error(g, res, exact).rms(), tol::kDomeRms);
  EXPECT_LT(strain_error(g, res, exact, /*border=*/0).rms(), 2 * tol::kDomeRms);
  double s = 0, t = 0;
  for (unsigned seed = 1; seed <= 2; ++seed) {
    go.noise = tol::kNoise;
    go.seed = seed;
    g = make_synthetic_grid(synthetic_case("dome"), go, &exact);
    AnalyseOptions o;
    s += strain_error(g, analyse(g, o), exact).rms();
    o.method = Method::kTriangles;
    t += strain_error(g, analyse(g, o), exact).rms();
  }
  EXPECT_LT(s, tol::kNoisyCurvedRatio * t) << "ratio " << s / t;
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

struct NoisyCase {
  std::string name;
  double ratio;  // bound on surface / triangles RMS error
};
void PrintTo(const NoisyCase& c, std::ostream* os) { *os << c.name; }

class Noisy : public ::testing::TestWithParam<NoisyCase> {};
TEST_P(Noisy, SurfaceBeatsTriangles) {
  const auto [s, t] = noisy_errors(GetParam().name);
  EXPECT_LT(s, GetParam().ratio * t) << "surface rms " << s << ", triangles rms " << t << ", ratio " << s / t;
}
INSTANTIATE_TEST_SUITE_P(
    GsaAccuracy, Noisy,
    ::testing::Values(NoisyCase{"rigid", tol::kNoisyFlatRatio}, NoisyCase{"stretch", tol::kNoisyFlatRatio},
                      NoisyCase{"dome", tol::kNoisyCurvedRatio}, NoisyCase{"cylinder", tol::kNoisyCurvedRatio},
                      NoisyCase{"trellis", tol::kNoisyCurvedRatio}, NoisyCase{"wavy", tol::kNoisyCurvedRatio}),
    [](const ::testing::TestParamInfo<NoisyCase>& p) { return p.param.name; });

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
  const auto [dd, idd] =
      worst(r, [&](Index, const SurfaceStrain& s) { return 1.0 - std::abs(s.dir1_deformed.dot(d1)); });
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

// Points the measuring system marked invalid are reported as not_measured (both methods).
TEST(GsaMissing, PointsTheSystemMarkedInvalidAreNotMeasured) {
  GridData g = make_synthetic_grid(synthetic_case("stretch"), {});
  g.not_measured.assign(static_cast<std::size_t>(g.n_points()), 0);
  const Index a = 3 * 21 + 4, b = 10 * 21 + 10;
  g.deformed.row(a).setConstant(std::numeric_limits<double>::quiet_NaN());
  g.not_measured[static_cast<std::size_t>(a)] = io::kNotMeasuredDeformed;
  g.deformed.row(b).setConstant(std::numeric_limits<double>::quiet_NaN());  // simply missing
  for (const Method m : {Method::kSurface, Method::kTriangles}) {
    AnalyseOptions o;
    o.method = m;
    const AnalysisResult res = analyse(g, o);
    EXPECT_EQ(res.points[a].status, kStatusNotMeasured);
    EXPECT_FALSE(res.points[a].strain);
    EXPECT_EQ(res.points[b].status, kStatusMissingDeformed);
  }
}

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

// Checks that exactly the moved marks are flagged outlier_deformed.
void expect_only_moved_marks_flagged(const GridData& g, const AnalysisResult& res) {
  const std::vector<Index> moved = moved_marks(g.n_points());
  for (Index p = 0; p < g.n_points(); ++p) {
    if (std::find(moved.begin(), moved.end(), p) != moved.end()) {
      EXPECT_EQ(res.points[p].status, kStatusOutlierDeformed) << g.ids[p];
      EXPECT_TRUE(res.points[p].strain) << g.ids[p] << ": a flagged mark still gets the fitted surfaces' strain";
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
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms(), tol::kOutlierRemovedRel * e0.rms())
      << "with outliers: " << describe(e) << "; without: " << describe(e0);
}
INSTANTIATE_TEST_SUITE_P(GsaMissing, NoisyOutliers, ::testing::Values("dome", "cylinder"));

// Regression (was a library bug): on a noise-free grid, good marks next to an
// outlier were flagged too. Input: make_synthetic_grid(dome, {.outliers = 2}) --
// marks P7_0 and P6_2 moved 2 mm; P6_0, P7_2 and P8_0 (their neighbours) came out
// "outlier_deformed": all marks above max(6 sigma, 0.02 d) were dropped in one pass
// after a fit the outliers themselves pulled (noise estimate ~0, threshold 0.1 mm).
// Fixed by readmitting flagged marks that the final fit matches.
TEST(GsaMissing, NoiseFreeOutliersAreTheOnlyMarksFlagged) {
  SyntheticGridOptions go;
  go.outliers = 2;
  std::vector<ExactStrain> exact;
  const GridData g = make_synthetic_grid(synthetic_case("dome"), go, &exact);
  const AnalysisResult res = analyse(g, {});
  expect_only_moved_marks_flagged(g, res);
  const StrainError e = strain_error(g, res, exact);
  EXPECT_EQ(e.n_missing, 0);
  EXPECT_LT(e.rms(), tol::kDomeDegradedRms) << describe(e);
}

// A dense grid with nothing but Gaussian noise: no mark is an outlier, and the
// reported noise estimate is the noise. (The undeformed residuals are normal
// distances, one component: judged as 3-D vectors, 0.14 % of the marks of a 1e5
// grid were flagged, and the estimate came out as sigma / sqrt(3).) Measured:
// 0 flagged, estimate 0.00998 for sigma 0.01.
TEST(GsaMissing, PureNoiseOnADenseGridFlagsNoMark) {
  SyntheticGridOptions go;
  go.n = 100;
  go.spacing = 1.0;
  go.noise = tol::kNoise;
  const GridData g = make_synthetic_grid(synthetic_case("dome"), go);
  const AnalysisResult res = analyse(g, {});
  Index flagged = 0;
  for (const PointResult& p : res.points) flagged += p.status != kStatusOk;
  EXPECT_EQ(flagged, 0);
  EXPECT_NEAR(res.noise_estimate, tol::kNoise, 0.1 * tol::kNoise);
}

// ---------------------------------------------------------------- fibre mode

// Largest errors of the fibre stretches and of the shear angle against the exact map,
// over the interior marks, with where they occur.
struct FibreErrors {
  double stretch = 0, shear_deg = 0;
  std::string stretch_at, shear_at;
  Index n = 0;
};
FibreErrors fibre_errors(const std::string& name, const GridData& g, const AnalysisResult& res,
                         const std::vector<double>& angles) {
  const SyntheticCase& c = synthetic_case(name);
  long imax = 0;
  for (Index p = 0; p < g.n_points(); ++p) imax = std::max({imax, g.i[p], g.j[p]});
  FibreErrors e;
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  for (Index p = 0; p < g.n_points(); ++p) {
    const PointResult& pr = res.points[p];
    if (g.i[p] < 1 || g.j[p] < 1 || g.i[p] >= imax || g.j[p] >= imax) continue;
    EXPECT_TRUE(pr.strain) << g.ids[p];
    if (!pr.strain) continue;
    EXPECT_EQ(pr.fibres.size(), 2u) << g.ids[p];
    if (pr.fibres.size() != 2) continue;
    const Vec3 X = g.undeformed.row(p).transpose();
    Vec3 dir[2];
    for (int k = 0; k < 2; ++k) {
      const double t = angles[k] / kDeg;
      const Vec3 a0(std::cos(t), std::sin(t), 0.0);  // on the flat blank, anticlockwise from X seen from +Z
      const Vec3 a = (c.map(X + tol::kFibreFdStep * a0) - c.map(X - tol::kFibreFdStep * a0)) / (2 * tol::kFibreFdStep);
      dir[k] = a.normalized();
      const double d = std::abs(pr.fibres[k].stretch - a.norm());
      if (!(d <= e.stretch)) e.stretch = d, e.stretch_at = g.ids[p] + " fibre " + std::to_string(k + 1);
    }
    const double shear = std::abs(angles[1] - angles[0]) - std::acos(std::clamp(dir[0].dot(dir[1]), -1.0, 1.0)) * kDeg;
    const double d = std::abs(pr.shear_angle_deg - shear);
    if (!(d <= e.shear_deg)) e.shear_deg = d, e.shear_at = g.ids[p];
    ++e.n;
  }
  return e;
}

struct FibreCase {
  std::string name;
  Method method;
  bool ij;  // false: drop i, j (triangles: Delaunay)
  std::vector<double> angles;
};
std::string fibre_case_label(const FibreCase& c) {
  std::string s = c.name + (c.method == Method::kSurface ? "_surface" : "_triangles") + (c.ij ? "" : "_noij");
  for (double a : c.angles) s += (a < 0 ? "_m" : "_") + std::to_string(static_cast<int>(std::abs(a)));
  return s;
}
std::string fibre_case_name(const ::testing::TestParamInfo<FibreCase>& info) { return fibre_case_label(info.param); }
void PrintTo(const FibreCase& c, std::ostream* os) { *os << fibre_case_label(c); }
FibreErrors run_fibre_case(const FibreCase& fc) {
  const GridData with_ij = make_synthetic_grid(synthetic_case(fc.name), {});
  GridData g = with_ij;
  if (!fc.ij) {
    g.has_ij = false;
    g.i.clear();
    g.j.clear();
  }
  AnalyseOptions o;
  o.method = fc.method;
  o.fibre_angles = fc.angles;
  return fibre_errors(fc.name, with_ij, analyse(g, o), fc.angles);
}

// Homogeneous simple shear: both methods exact, for any pair of fibre angles.
class FibresExact : public ::testing::TestWithParam<FibreCase> {};
TEST_P(FibresExact, MatchTheExactMap) {
  const FibreErrors e = run_fibre_case(GetParam());
  EXPECT_GT(e.n, 300);
  EXPECT_LT(e.stretch, tol::kExactFibreStretch) << "at " << e.stretch_at;
  EXPECT_LT(e.shear_deg, tol::kExactShearDeg) << "at " << e.shear_at;
}
INSTANTIATE_TEST_SUITE_P(GsaFibres, FibresExact,
                         ::testing::Values(FibreCase{"shear", Method::kSurface, true, {0, 90}},
                                           FibreCase{"shear", Method::kSurface, true, {-45, 45}},
                                           FibreCase{"shear", Method::kSurface, true, {-30, 60}},
                                           FibreCase{"stretch", Method::kSurface, true, {-30, 60}}),
                         fibre_case_name);

// LIBRARY BUG (reported to the lead): the triangles method in fibre mode measures the
// fibre angles CLOCKWISE seen from +Z when it uses grid (i, j) triangles. Input:
// make_synthetic_grid(shear) (x = X + 0.3 Y, homogeneous, so per-triangle strain is
// exact), --method triangles --fibres 0,90: shear_angle_deg = -16.7 instead of +16.7
// at every mark (error 33.4 degrees); --fibres -45,45: fibre stretches off by up to
// 0.30 (the +45 and -45 fibres swapped). On the dome, errors up to 15 degrees.
// Cause (gsa/triangles.cpp): the fibre frame is oriented by the summed triangle
// normals G1 x G2, and grid_triangles() lists every triangle clockwise seen from +Z
// (normal -Z). The Delaunay path (no i, j) passes here, but its sense comes from the
// signs of the eigen-solver's plane axes, not from +Z. Expected: the convention of
// the surface method and docs/usage.md ("anticlockwise seen from +Z"; normal of the
// best-fit plane oriented towards +Z), i.e. exact results on this grid. (Cases that
// are mirror-symmetric, like stretch with -30,60, cannot see the bug and pass.)
class FibresExactTriangles : public ::testing::TestWithParam<FibreCase> {};
TEST_P(FibresExactTriangles, MatchTheExactMap) {
  const FibreErrors e = run_fibre_case(GetParam());
  EXPECT_GT(e.n, 300);
  EXPECT_LT(e.stretch, tol::kExactFibreStretch) << "at " << e.stretch_at;
  EXPECT_LT(e.shear_deg, tol::kExactShearDeg) << "at " << e.shear_at;
}
INSTANTIATE_TEST_SUITE_P(GsaFibres, FibresExactTriangles,
                         ::testing::Values(FibreCase{"shear", Method::kTriangles, true, {0, 90}},
                                           FibreCase{"shear", Method::kTriangles, true, {-45, 45}},
                                           FibreCase{"shear", Method::kTriangles, false, {0, 90}},
                                           FibreCase{"shear", Method::kTriangles, false, {-30, 60}},
                                           FibreCase{"stretch", Method::kTriangles, false, {-30, 60}},
                                           FibreCase{"stretch", Method::kTriangles, true, {-30, 60}}),
                         fibre_case_name);

// Curved parts: the surface method within the curved-case bounds.
class FibresCurved : public ::testing::TestWithParam<FibreCase> {};
TEST_P(FibresCurved, MatchTheExactMap) {
  const FibreErrors e = run_fibre_case(GetParam());
  EXPECT_GT(e.n, 300);
  const bool surface = GetParam().method == Method::kSurface;
  EXPECT_LT(e.stretch, surface ? tol::kCurvedFibreStretch : tol::kTrianglesCurvedFibreStretch) << "at " << e.stretch_at;
  EXPECT_LT(e.shear_deg, surface ? tol::kCurvedShearDeg : tol::kTrianglesCurvedShearDeg) << "at " << e.shear_at;
}
INSTANTIATE_TEST_SUITE_P(GsaFibres, FibresCurved,
                         ::testing::Values(FibreCase{"dome", Method::kSurface, true, {0, 90}},
                                           FibreCase{"dome", Method::kSurface, true, {-30, 60}},
                                           FibreCase{"wavy", Method::kSurface, true, {-45, 45}},
                                           FibreCase{"wavy", Method::kSurface, true, {0, 90}}),
                         fibre_case_name);

// Same bug as FibresExactTriangles, on the dome (measured errors up to 15 degrees).
class FibresCurvedTriangles : public ::testing::TestWithParam<FibreCase> {};
TEST_P(FibresCurvedTriangles, MatchTheExactMap) {
  const FibreErrors e = run_fibre_case(GetParam());
  EXPECT_GT(e.n, 300);
  EXPECT_LT(e.stretch, tol::kTrianglesCurvedFibreStretch) << "at " << e.stretch_at;
  EXPECT_LT(e.shear_deg, tol::kTrianglesCurvedShearDeg) << "at " << e.shear_at;
}
INSTANTIATE_TEST_SUITE_P(GsaFibres, FibresCurvedTriangles,
                         ::testing::Values(FibreCase{"dome", Method::kTriangles, true, {0, 90}},
                                           FibreCase{"dome", Method::kTriangles, true, {-30, 60}},
                                           FibreCase{"dome", Method::kTriangles, false, {-30, 60}}),
                         fibre_case_name);

// ---------------------------------------------------------------- sample data

// A sample grid of data/gsa/ with its exact strains (exact.csv, same ids).
struct Sample {
  GridData grid;
  std::vector<ExactStrain> exact;
};
Sample read_sample(const std::string& name) {
  const std::string dir = std::string(SF_SOURCE_DIR) + "/data/gsa/" + name;
  Sample s;
  s.grid = read_grid(dir + "/grid.csv");
  const io::CsvTable t = io::read_csv(dir + "/exact.csv");
  std::map<std::string, std::size_t> row;
  for (std::size_t r = 0; r < t.n_rows(); ++r) row[std::string(t.cell(r, t.column_index("id")))] = r;
  for (const std::string& id : s.grid.ids) {
    const std::size_t r = row.at(id);
    s.exact.push_back({t.number(r, t.column_index("lambda1")), t.number(r, t.column_index("lambda2")),
                       t.number(r, t.column_index("shear_angle_deg"))});
  }
  EXPECT_TRUE(s.grid.has_ij) << name;
  return s;
}

TEST(GsaSamples, NoiseFreeSamplesMatchTheirExactStrains) {
  const std::pair<const char*, double> cases[] = {
      {"dome", tol::kDomeRms}, {"cylinder", tol::kCylinderRms}, {"trellis", tol::kTrellisRms}};
  for (const auto& [name, bound] : cases) {
    SCOPED_TRACE(name);
    const Sample s = read_sample(name);
    AnalyseOptions o;
    if (std::string(name) == "trellis") o.fibre_angles = {0, 90};
    const AnalysisResult res = analyse(s.grid, o);
    EXPECT_EQ(count_status(res, kStatusOk), s.grid.n_points());
    const StrainError e = strain_error(s.grid, res, s.exact);
    EXPECT_LT(e.rms(), bound) << describe(e);
    if (std::string(name) == "trellis") {
      EXPECT_LT(e.rms_shear_deg, tol::kTrellisShearDeg) << describe(e);
    }
  }
}

TEST(GsaSamples, NoisyDomeAsDocumented) {
  // docs/usage.md: 423 ok, 16 missing_deformed, 2 outlier_deformed (P6_2 and P7_0).
  const Sample s = read_sample("dome_noisy");
  const AnalysisResult res = analyse(s.grid, {});
  EXPECT_EQ(count_status(res, kStatusOk), 423);
  EXPECT_EQ(count_status(res, kStatusMissingDeformed), 16);
  std::vector<std::string> outliers;
  for (Index p = 0; p < s.grid.n_points(); ++p)
    if (res.points[p].status == kStatusOutlierDeformed) outliers.push_back(s.grid.ids[p]);
  EXPECT_THAT(outliers, ::testing::UnorderedElementsAre("P6_2", "P7_0"));
  const StrainError e = strain_error(s.grid, res, s.exact);
  EXPECT_LT(e.rms(), tol::kSampleNoisyDomeRms) << describe(e);
}

}  // namespace
}  // namespace sf::gsa
