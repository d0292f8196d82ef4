// gsa on real exports of measuring systems (data/real/README.md), against the strains
// the systems computed themselves from the same points: every measured point gets a
// strain, nothing real is flagged, and gsa's strains agree with the system's within the
// difference measured when these files were added (docs/usage.md, "Real exports"). The
// systems smooth differently (DICe: a 360-pixel virtual strain gauge, about 10 subset
// spacings; ARAMIS: its own strain neighbourhood over a few facets), so the tolerance is
// that difference with a margin, not a claim that either is exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/io/csv.hpp"
#include "common/io/grid_file.hpp"
#include "gsa/analysis.hpp"

namespace sf::gsa {
namespace {

std::string real_dir() { return std::string(SF_SOURCE_DIR) + "/data/real/"; }

// The system's strain components per point id (the id as the reader makes it).
struct SystemStrains {
  std::unordered_map<std::string, std::pair<double, double>> xx_yy;
};

// Reads the columns `xx`, `yy` of the table whose header holds them, scaled by `scale`;
// the id is the cells of `key` joined with '_'.
SystemStrains read_system(const std::string& path, const std::vector<std::string>& key, const std::string& xx,
                          const std::string& yy, double scale) {
  io::CsvOptions o;
  o.delimiter = io::kDetectDelimiter;
  o.brackets_in_header = true;
  o.header_test = [&](const std::vector<std::string>& names) {
    return std::find(names.begin(), names.end(), xx) != names.end() &&
           std::find(names.begin(), names.end(), yy) != names.end();
  };
  const io::CsvTable t = io::read_csv(path, o);
  std::vector<std::size_t> kc;
  for (const std::string& k : key) kc.push_back(t.column_index(k));
  const std::size_t cx = t.column_index(xx), cy = t.column_index(yy);
  SystemStrains s;
  for (std::size_t r = 0; r < t.n_rows(); ++r) {
    std::string id;
    for (std::size_t k = 0; k < kc.size(); ++k) id += (k ? "_" : "") + std::string(t.cell(r, kc[k]));
    const double a = t.number(r, cx, true), b = t.number(r, cy, true);
    if (std::isfinite(a) && std::isfinite(b)) s.xx_yy[id] = {a * scale, b * scale};
  }
  return s;
}

// The stretch of the material line along `e` (projected onto the undeformed surface).
double line_stretch(const SurfaceStrain& s, const Vec3& e) {
  Vec3 t = e - e.dot(s.normal_undeformed) * s.normal_undeformed;
  t.normalize();
  const double a = s.dir1_undeformed.dot(t), b = s.dir2_undeformed.dot(t);
  return std::sqrt(s.lambda1 * s.lambda1 * a * a + s.lambda2 * s.lambda2 * b * b);
}

enum class Measure { kGreen, kTechnical };
double strain_of(double stretch, Measure m) {
  return m == Measure::kGreen ? 0.5 * (stretch * stretch - 1.0) : stretch - 1.0;
}

struct Agreement {
  Index compared = 0, measured = 0, without_strain = 0, flagged = 0;
  double rms_xx = 0, rms_yy = 0, bias_xx = 0, bias_yy = 0;
  double peak_yy_gsa = -1e9, peak_yy_system = -1e9;
};

Agreement compare(const GridData& g, const AnalysisResult& r, const SystemStrains& sys, Measure m) {
  Agreement a;
  for (Index p = 0; p < g.n_points(); ++p) {
    const PointResult& pr = r.points[static_cast<std::size_t>(p)];
    if (pr.flag) ++a.flagged;
    if (!g.has_undeformed(p) || !g.has_deformed(p)) continue;
    ++a.measured;
    if (!pr.strain) {
      ++a.without_strain;
      continue;
    }
    const auto it = sys.xx_yy.find(g.ids[static_cast<std::size_t>(p)]);
    if (it == sys.xx_yy.end()) continue;
    const double xx = strain_of(line_stretch(*pr.strain, Vec3::UnitX()), m);
    const double yy = strain_of(line_stretch(*pr.strain, Vec3::UnitY()), m);
    const double dx = xx - it->second.first, dy = yy - it->second.second;
    a.rms_xx += dx * dx, a.rms_yy += dy * dy, a.bias_xx += dx, a.bias_yy += dy;
    a.peak_yy_gsa = std::max(a.peak_yy_gsa, yy);
    a.peak_yy_system = std::max(a.peak_yy_system, it->second.second);
    ++a.compared;
  }
  if (a.compared) {
    const double n = static_cast<double>(a.compared);
    a.rms_xx = std::sqrt(a.rms_xx / n), a.rms_yy = std::sqrt(a.rms_yy / n);
    a.bias_xx /= n, a.bias_yy /= n;
  }
  std::printf(
      "compared %ld of %ld measured points (%ld without strain, %ld flagged): RMS xx %.3g yy %.3g, bias xx %.3g "
      "yy %.3g, peak yy gsa %.4g system %.4g\n",
      static_cast<long>(a.compared), static_cast<long>(a.measured), static_cast<long>(a.without_strain),
      static_cast<long>(a.flagged), a.rms_xx, a.rms_yy, a.bias_xx, a.bias_yy, a.peak_yy_gsa, a.peak_yy_system);
  return a;
}

// DICe, open-hole CFRP coupon of the DIC Challenge, image 11 (about 0.7 % axial strain,
// 1.1 % beside the hole): 230 subsets 35 pixels apart, read in pixels.
TEST(GsaRealExports, DiceOpenHoleCouponAgreesWithDicesStrainGauge) {
  const std::string path = real_dir() + "dice_oht_cfrp/DICe_solution_11.txt";
  GridReadOptions o;
  o.format = io::MeasurementFormat::kAuto;
  o.units = "px";
  const GridData g = io::read_grid_file(path, o);
  const AnalysisResult r = analyse(g, {});
  const SystemStrains sys = read_system(path, {"COORDINATE_X", "COORDINATE_Y"}, "VSG_STRAIN_XX", "VSG_STRAIN_YY", 1.0);
  const Agreement a = compare(g, r, sys, Measure::kGreen);
  EXPECT_EQ(a.measured, 230);
  EXPECT_EQ(a.without_strain, 0);
  EXPECT_EQ(a.compared, 230);
  EXPECT_EQ(a.flagged, 0);
  // Measured when added: RMS 9.8e-4 (xx), 1.7e-3 (yy), bias 1.9e-4 and -4.2e-4, peak E_yy
  // 1.27 % beside the hole against DICe's 1.09 % (its 360-pixel gauge flattens the
  // concentration). gsa's automatic gauge is 12.6 px, 0.38 subset spacings (GCV on
  // independent noise: the 27-pixel subsets 35 pixels apart share no pixels).
  EXPECT_LT(a.rms_xx, 1.5e-3);
  EXPECT_LT(a.rms_yy, 2.5e-3);
  EXPECT_LT(std::abs(a.bias_xx), 1e-3);
  EXPECT_LT(std::abs(a.bias_yy), 1e-3);
  EXPECT_GT(a.peak_yy_gsa, 0.9 * a.peak_yy_system);
  EXPECT_LT(a.peak_yy_gsa, 1.5 * a.peak_yy_system);
}

// ARAMIS, fatigue crack in an MT specimen, stage 52: 166 measured facets ahead of the
// crack tip and along the crack, where the opening shows as a band of eps_y up to 3 %
// two facets wide (the system's own strains, in %, technical).
TEST(GsaRealExports, AramisCrackBandIsKeptAndAgreesWithAramis) {
  const std::string path = real_dir() + "aramis_mt_crack/nodemap_stage52_crack_tip.txt";
  GridReadOptions o;
  o.format = io::MeasurementFormat::kAuto;
  const GridData g = io::read_grid_file(path, o);
  const AnalysisResult r = analyse(g, {});
  const SystemStrains sys = read_system(path, {"ID"}, "epsx [%]", "epsy [%]", 0.01);
  const Agreement a = compare(g, r, sys, Measure::kTechnical);
  EXPECT_EQ(a.measured, 166);
  EXPECT_EQ(a.without_strain, 0);
  EXPECT_EQ(a.compared, 166);
  // Two facets beside the centre notch (24011 in the band, 24403 below it) stand
  // 0.035-0.040 mm off their neighbours' undeformed surface (threshold 0.021 mm): flagged
  // as blunders of the undeformed state, their strains kept (without_strain above).
  EXPECT_LE(a.flagged, 2);
  // Measured when added: RMS 1.5e-3 (xx), 6.1e-3 (yy), bias 1.6e-4 and -8.3e-4; the band's
  // peak eps_y 1.98 % against ARAMIS's 3.00 %: the band is two facets (1.4 mm) wide, under
  // the automatic 4.2 mm gauge and the 1.6 x 2.1 mm elements (docs/usage.md, "Real
  // exports"). Since the strain test of the local relaxation (GCV chose its heaviest
  // weight; the fit's strain misses the residuals' local gradient along the crack): 11 of
  // 18 elements relaxed, GCV then a 0.85 mm gauge, 0.48 mm in the relaxed elements, no
  // refinement; RMS 8.5e-4, 4.3e-3, bias 8.7e-5, -6.1e-4, peak 2.85 %. Without the strain
  // test this fails (peak 0.66 of ARAMIS's, RMS yy 6.1e-3, nothing relaxed).
  EXPECT_GT(r.relaxed_elements, 0);
  EXPECT_LT(r.local_gauge_length, r.gauge_length);
  EXPECT_LT(a.rms_xx, 2.5e-3);
  EXPECT_LT(a.rms_yy, 5e-3);
  EXPECT_LT(std::abs(a.bias_yy), 2e-3);
  EXPECT_GT(a.peak_yy_gsa, 0.85 * a.peak_yy_system);
  EXPECT_LT(a.peak_yy_gsa, 1.3 * a.peak_yy_system);
}

}  // namespace
}  // namespace sf::gsa
