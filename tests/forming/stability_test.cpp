// Buckling stability of trellis flows (forming/stability/, docs/theory/stability.md):
//   - the closed forms against an independent Legendre-Galerkin solution of the full
//     linearised equations, fibre-reinforced (over a range of fibre angles, tensions, rates,
//     directions and wave numbers) and Newtonian (sinuous and varicose, arbitrary rates);
//   - the Newtonian sheet's exact Stokes solution substituted back into its equations;
//   - limits: the isotropic (no fibre) sheet at long waves against the thin viscous sheet
//     (viscida) of Buckmaster, Nachman & Ting (1975), the fibre sheet at long waves against
//     the membrane argument (growth relative to the thickness iff T_n < 0), symmetry under
//     theta -> -theta with the fibre angles mirrored;
//   - the background: trellis rates keep both families inextensible, D33 = gamma_dot cot chi,
//     tractions give back the tensions and rate that produced them;
//   - bad input names the option or FILE:LINE:COLUMN; outputs written with no display.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "common/render/scene.hpp"
#include "forming/stability/analysis.hpp"
#include "forming/stability/input.hpp"
#include "forming/stability/output.hpp"
#include "forming/stability/sheet.hpp"
#include "forming/stability/spectral.hpp"
#include "forming/stability/trellis.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::forming::stability {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = kPi / 180.0;

// ---- Named tolerances ------------------------------------------------------------
namespace tol {
// Fibre sheet: the Galerkin solution represents the exact fields (u = W e3, xi = w e3)
// exactly, so only roundoff of the SVDs and solves remains (measured <= 3e-15 relative).
inline constexpr double kFibreSpectralRel = 1e-10;
// Newtonian sheet, degree 24, K h <= 10: the fields are cosh/sinh through the thickness,
// whose Legendre coefficients beyond 24 are below 1e-12 (measured <= 2e-13 relative).
inline constexpr double kNewtonianSpectralRel = 1e-9;
// Identities that hold exactly (symmetry, rearranged formulas): roundoff of a few flops.
inline constexpr double kExact = 1e-12;
// Long-wave expansion of the exact sinuous growth rate: (G - D33) / (-3 S / (mu q^2))
// = 1 - q^2 / 20 + O(q^4); at q = 0.05 the O(q^4) rest is ~ 1e-7.
inline constexpr double kLongWaveRest = 1e-6;
// The trellis rates built from the fibre directions (a.D.a, b.D.b relative to |D|).
inline constexpr double kInextensible = 1e-13;
}  // namespace tol

TrellisSpec spec(double angle_a, double angle_b, double shear_rate, double ta, double tb) {
  TrellisSpec s;
  s.fibre_angles_deg = {angle_a, angle_b};
  s.viscosity = 2e-3;
  s.thickness = 1.5;
  s.shear_rate = shear_rate;
  s.tensions = std::array<double, 2>{ta, tb};
  return s;
}

// ---- background ------------------------------------------------------------------

TEST(StabilityTrellis, UnitRateKeepsBothFamiliesInextensibleAndGivesDThree) {
  std::mt19937 rng(sf::test::kSeed);
  std::uniform_real_distribution<double> ang(-180.0, 180.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double aa = ang(rng), ab = ang(rng);
    const Vec2 a(std::cos(aa * kDeg), std::sin(aa * kDeg)), b(std::cos(ab * kDeg), std::sin(ab * kDeg));
    const double sin_chi = std::abs(a.x() * b.y() - a.y() * b.x());
    if (sin_chi < 0.05) continue;
    const Mat2 u = unit_trellis_rate(a, b);
    EXPECT_NEAR(a.dot(u * a), 0.0, tol::kInextensible * u.norm()) << aa << " " << ab;
    EXPECT_NEAR(b.dot(u * b), 0.0, tol::kInextensible * u.norm());
    EXPECT_NEAR(trellis_shear_rate(u, a, b), 1.0, tol::kExact);
    // The angle between the families closes at gamma_dot: d(a.b)/dt = 2 a.D.b.
    const double chi = std::acos(a.dot(b));
    EXPECT_NEAR(-u.trace(), std::cos(chi) / std::sin(chi), 1e-12 * (1 + std::abs(u.trace())));
  }
}

TEST(StabilityTrellis, TractionsGiveBackTheTensionsAndRate) {
  const TrellisFlow f = build_trellis_flow(spec(25.0, -40.0, 0.7, 0.03, -0.011));
  const Mat2 s = f.sheet.in_plane_stress();
  TrellisSpec t = spec(25.0, -40.0, 0.0, 0.0, 0.0);
  t.shear_rate.reset();
  t.tensions.reset();
  t.tractions = std::array<double, 3>{s(0, 0), s(1, 1), s(0, 1)};
  const TrellisFlow g = build_trellis_flow(t);
  EXPECT_NEAR(g.shear_rate, 0.7, 1e-12);
  EXPECT_NEAR(g.sheet.fibres[0].tension, 0.03, 1e-14);
  EXPECT_NEAR(g.sheet.fibres[1].tension, -0.011, 1e-14);
  EXPECT_EQ(g.source, TrellisFlow::Source::kTractions);
}

TEST(StabilityTrellis, ThickeningAndThinningFollowTheFibreAngle) {
  // Fibres closing (gamma_dot > 0) at chi < 90 deg: the sheet thickens; at chi > 90 it thins.
  EXPECT_TRUE(build_trellis_flow(spec(30, -30, 1.0, 0, 0)).thickening());
  EXPECT_TRUE(build_trellis_flow(spec(60, -60, 1.0, 0, 0)).thinning());
  EXPECT_TRUE(build_trellis_flow(spec(30, -30, -1.0, 0, 0)).thinning());
  const TrellisFlow f = build_trellis_flow(spec(45, -45, 1.0, 0, 0));
  EXPECT_NEAR(f.sheet.rate33(), 0.0, tol::kExact);
}

void expect_input_error(const TrellisSpec& s, const std::string& pattern) {
  try {
    build_trellis_flow(s);
    ADD_FAILURE() << "no error, expected " << pattern;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), testing::ContainsRegex(pattern));
  }
}

TEST(StabilityTrellis, BadInputNamesTheOption) {
  TrellisSpec s = spec(30, -30, 1.0, 0.01, 0.01);
  s.viscosity = -1;
  expect_input_error(s, "^--viscosity: expected a positive viscosity \\(MPa s\\), found -1");
  s = spec(30, 210, 1.0, 0.01, 0.01);
  expect_input_error(s, "^--fibres: .*parallel.*degenerate");
  s = spec(30, -30, 1.0, 0.01, 0.01);
  s.thickness = 0;
  expect_input_error(s, "^--thickness: expected a positive thickness");
  // Rates that stretch the fibres, with the nearest trellis rate suggested.
  s = spec(30, -30, 0, 0.01, 0.01);
  s.shear_rate.reset();
  s.rates = std::array<double, 3>{1.0, 1.0, 0.0};
  expect_input_error(s, "^--rates: .*stretches the fibres .*allow only trellis rates.*nearest");
  // A trellis rate (D11, D22) = (1, -3) for +-30 deg, with a wrong D33.
  s.rates = std::array<double, 3>{1.0, -3.0, 0.0};
  s.rate33 = 1.0;
  expect_input_error(s, "^--rate33: D33 = 1 1/s violates incompressibility: .* must be -\\(D11 \\+ D22\\) = 2");
  s.rate33 = 2.0;
  EXPECT_NO_THROW(build_trellis_flow(s));
  s = spec(30, -30, 1.0, 0.01, 0.01);
  s.tractions = std::array<double, 3>{0.0, 0.0, 0.0};
  expect_input_error(s, "^--tractions: give either the fibre tensions");
  s = spec(30, -30, 1.0, 0.01, 0.01);
  s.tensions.reset();
  expect_input_error(s, "^--tensions: missing");
}

// ---- closed forms ----------------------------------------------------------------

TEST(StabilityClosedForm, FibreSheetGrowthIsDThreeMinusResolvedTension) {
  std::mt19937 rng(sf::test::kSeed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const double aa = 90 * u(rng), ab = aa + 20 + 70 * (1 + u(rng));
    const TrellisFlow f = build_trellis_flow(spec(aa, ab, u(rng), 0.01 * u(rng), 0.01 * u(rng)));
    const double theta = kPi * u(rng);
    // Written out with the angles: T_n = T_a cos^2(theta - alpha_a) + T_b cos^2(theta - alpha_b).
    const double tn = f.sheet.fibres[0].tension * std::pow(std::cos(theta - aa * kDeg), 2) +
                      f.sheet.fibres[1].tension * std::pow(std::cos(theta - ab * kDeg), 2);
    EXPECT_NEAR(fibre_sheet_growth_rate(f.sheet, theta), f.sheet.rate33() - tn / f.sheet.viscosity,
                tol::kExact * (1 + std::abs(tn / f.sheet.viscosity)));
    // Non-dimensional form: Gamma = s |cot chi| - tau.
    if (std::abs(f.shear_rate) > 1e-3 && std::abs(f.sheet.rate33()) > 1e-9) {
      const double tau = tn / (f.sheet.viscosity * std::abs(f.shear_rate));
      const FlowKind k = f.thickening() ? FlowKind::kThickening : FlowKind::kThinning;
      EXPECT_NEAR(growth_factor(tau, f.fibre_angle, k),
                  fibre_sheet_growth_rate(f.sheet, theta) / std::abs(f.shear_rate), 1e-10 * (1 + std::abs(tau)));
    }
  }
}

TEST(StabilityClosedForm, NewtonianExactSolutionSatisfiesItsEquations) {
  // Sinuous mode of the free layer |z| <= H: stream function f(z) = A cosh Kz + B z sinh Kz,
  // u_s = f', u_z = -i K f; with A = -B H coth KH and B = i S eta sinh KH / (2 mu (sinh KH
  // cosh KH - KH)) (docs/theory/stability.md, section 5) the tangential traction
  // mu (f'' + K^2 f) = i K S eta and the normal traction (i mu / K)(f''' - 3 K^2 f') = 0 hold
  // at z = H, and u_z(H) / eta is the growth rate's closed form minus D33.
  const double mu = 1.3, s = -0.7, eta = 1.0;
  for (double q : {0.2, 1.0, 3.0, 7.0}) {
    const double h = 2.0, k = q / h, hh = h / 2;
    const std::complex<double> i(0.0, 1.0);
    const std::complex<double> b =
        i * s * eta * std::sinh(k * hh) / (2.0 * mu * (std::sinh(k * hh) * std::cosh(k * hh) - k * hh));
    const std::complex<double> a = -b * hh * std::cosh(k * hh) / std::sinh(k * hh);
    const double z = hh, c = std::cosh(k * z), sh = std::sinh(k * z);
    const std::complex<double> f = a * c + b * z * sh;
    const std::complex<double> f1 = a * k * sh + b * (sh + k * z * c);
    const std::complex<double> f2 = a * k * k * c + b * (2.0 * k * c + k * k * z * sh);
    const std::complex<double> f3 = a * k * k * k * sh + b * (3.0 * k * k * sh + k * k * k * z * c);
    EXPECT_LT(std::abs(mu * (f2 + k * k * f) - i * k * s * eta), 1e-12) << q;
    EXPECT_LT(std::abs(f3 - 3.0 * k * k * f1), 1e-12 * std::abs(f3) + 1e-12) << q;
    const std::complex<double> uz = -i * k * f;
    // An in-plane rate with n.sigma.n = s along theta = 0: sigma_11 = 2 mu (2 D11 + D22) = s
    // with D22 = 0, D11 = s / (4 mu).
    Mat2 rate;
    rate << s / (4.0 * mu), 0.0, 0.0, 0.0;
    const NewtonianGrowthRates g = newtonian_sheet_growth_rates(rate, mu, h, 0.0, k);
    EXPECT_NEAR(uz.real(), g.sinuous + rate.trace(), 1e-12 * (1 + std::abs(uz.real()))) << q;
    EXPECT_LT(std::abs(uz.imag()), 1e-12);
  }
}

// ---- the independent numerical solution --------------------------------------------

TEST(StabilitySpectral, FibreSheetMatchesTheClosedFormOverARange) {
  std::mt19937 rng(sf::test::kSeed + 2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  int n_cases = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const double aa = 90 * u(rng), ab = aa + 25 + 65 * (1 + u(rng));
    const TrellisFlow f = build_trellis_flow(spec(aa, ab, 2 * u(rng), 0.02 * u(rng), 0.02 * u(rng)));
    const double theta = kPi * u(rng);
    if (normal_to_fibre(f.sheet, theta, 0.05)) continue;
    const double kh = std::pow(10.0, -2.0 + 3.3 * (1 + u(rng)) / 2);  // 0.01 .. 20
    SpectralOptions o;
    o.degree = 12;
    const SpectralReport r = solve_spectral(f.sheet, theta, kh / f.sheet.thickness, o);
    ASSERT_TRUE(r.ok()) << r.brief();
    EXPECT_EQ(r.n_state, 1);  // only the uniform vertical shift is admissible
    const double closed = fibre_sheet_growth_rate(f.sheet, theta);
    const double scale = std::abs(closed) + std::abs(f.sheet.rate33()) +
                         std::abs(f.sheet.resolved_tension(wave_direction(theta))) / f.sheet.viscosity;
    const double e = std::abs(r.growth_rate - closed) / scale;
    worst = std::max(worst, e);
    ++n_cases;
    EXPECT_LT(e, tol::kFibreSpectralRel) << r.brief() << " closed " << closed;
  }
  EXPECT_GT(n_cases, 40);
  std::printf("fibre sheet: closed form vs spectral over %d cases, largest relative difference %.2e\n", n_cases, worst);
}

TEST(StabilitySpectral, NewtonianSheetMatchesTheExactStokesSolution) {
  // Arbitrary (not trellis) rates, no fibres: sinuous and varicose modes.
  std::mt19937 rng(sf::test::kSeed + 3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    SheetState s;
    s.rate << u(rng), 0.5 * u(rng), 0.5 * u(rng), u(rng);
    s.rate(1, 0) = s.rate(0, 1);
    s.viscosity = 0.5 + u(rng) * 0.4;
    s.thickness = 2.0;
    const double theta = kPi * u(rng);
    const double kh = std::pow(10.0, -1.3 + 2.3 * (1 + u(rng)) / 2);  // 0.05 .. 10
    const SpectralReport r = solve_spectral(s, theta, kh / s.thickness);
    ASSERT_TRUE(r.ok()) << r.brief();
    const NewtonianGrowthRates g =
        newtonian_sheet_growth_rates(s.rate, s.viscosity, s.thickness, theta, kh / s.thickness);
    const double scale = std::abs(g.sinuous) + std::abs(g.varicose) + s.rate.norm();
    worst = std::max({worst, std::abs(r.sinuous - g.sinuous) / scale, std::abs(r.varicose - g.varicose) / scale});
    EXPECT_LT(std::abs(r.sinuous - g.sinuous) / scale, tol::kNewtonianSpectralRel) << "Kh " << kh << " " << r.brief();
    EXPECT_LT(std::abs(r.varicose - g.varicose) / scale, tol::kNewtonianSpectralRel) << "Kh " << kh;
  }
  std::printf("Newtonian sheet: exact vs spectral (degree 24, K h 0.05..10), largest relative difference %.2e\n",
              worst);
}

TEST(StabilitySpectral, DirectionNormalToAFibreIsReportedNotHidden) {
  const TrellisFlow f = build_trellis_flow(spec(30, -30, 1.0, 0.01, -0.01));
  const double theta = (30.0 + 90.0) * kDeg;  // crests along family a
  EXPECT_TRUE(normal_to_fibre(f.sheet, theta));
  const SpectralReport r = solve_spectral(f.sheet, theta, 1.0);
  EXPECT_GT(r.n_state, 1) << r.brief();  // family a no longer pins the in-plane displacement
  // The buckle excites flow along b_perp (with a component along the crests): no normal
  // mode, said so, with the buckle's instantaneous rate (not the closed form's limit here).
  EXPECT_EQ(r.status, SpectralReport::Status::kNotNormalMode) << r.brief();
  EXPECT_GT(r.invariance_residual, 1e-3);
  EXPECT_TRUE(std::isfinite(r.growth_rate));
  // Orthogonal families: the most unstable direction is always normal to one of them, and
  // there the in-plane flow the buckle excites runs along the crests only, so the buckle's
  // instantaneous rate is the closed form.
  const StabilityResult x = analyse_stability(build_trellis_flow(spec(45, -45, 0.5, 0.004, -0.001)), ScanOptions{});
  EXPECT_TRUE(x.mode.normal_to_fibre);
  EXPECT_NEAR(x.mode.theta_deg, 135.0, 1e-9);
  EXPECT_NEAR(x.check.growth_rate, x.check_closed_form, 1e-10 * std::abs(x.check_closed_form));
}

// ---- limits ------------------------------------------------------------------------

TEST(StabilityLimits, IsotropicLongWavesAreTheThinViscousSheet) {
  // Buckmaster, Nachman & Ting (1975): a thin viscous sheet bends with the bending viscosity
  // mu h^3 / 3, so (mu h^3 / 3) K^4 dW/dt = -N_n K^2 W: G - D33 = -3 S_n / (mu (K h)^2).
  Mat2 rate;
  rate << -0.4, 0.1, 0.1, 0.25;  // compression along x1
  const double mu = 0.8, h = 1.0;
  const double s_n = 2.0 * mu * (rate(0, 0) + rate.trace());
  for (double q : {0.05, 0.02, 0.01}) {
    const NewtonianGrowthRates g = newtonian_sheet_growth_rates(rate, mu, h, 0.0, q / h);
    const double thin = -3.0 * s_n / (mu * q * q);
    const double ratio = (g.sinuous + rate.trace()) / thin;
    EXPECT_NEAR(ratio, 1.0 - q * q / 20.0, tol::kLongWaveRest) << q;
    EXPECT_GT(g.sinuous + rate.trace(), 0.0);  // compression: bending grows
  }
  // The spectral solution agrees at long waves too.
  SheetState s;
  s.rate = rate;
  s.viscosity = mu;
  s.thickness = h;
  const SpectralReport r = solve_spectral(s, 0.0, 0.05 / h);
  EXPECT_NEAR((r.sinuous + rate.trace()) / (-3.0 * s_n / (mu * 0.05 * 0.05)), 1.0 - 0.05 * 0.05 / 20.0,
              tol::kLongWaveRest);
}

TEST(StabilityLimits, FibreLongWavesFollowTheMembraneArgument) {
  // A sheet whose in-plane motion is locked by the fibres can only shear through its
  // thickness: the tilted fibres' membrane force N_n = T_n h against the transverse shear,
  // mu K^2 W h = -K^2 N_n w, so W / w = -T_n / mu: growth relative to the thickness iff the
  // resolved fibre tension T_n < 0, at long waves (and, in this model, at every other).
  std::mt19937 rng(sf::test::kSeed + 4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const TrellisFlow f = build_trellis_flow(spec(35, -35, u(rng), 0.01 * u(rng), 0.01 * u(rng)));
    const double theta = kPi * u(rng);
    if (normal_to_fibre(f.sheet, theta, 0.05)) continue;
    SpectralOptions o;
    o.degree = 8;
    const SpectralReport r = solve_spectral(f.sheet, theta, 1e-3 / f.sheet.thickness, o);
    ASSERT_TRUE(r.ok()) << r.brief();
    const double tn = f.sheet.resolved_tension(wave_direction(theta));
    const double rel_growth = r.growth_rate - f.sheet.rate33();
    EXPECT_EQ(rel_growth > 0.0, tn < 0.0) << tn;
    EXPECT_NEAR(rel_growth, -tn / f.sheet.viscosity, 1e-9 * (1 + std::abs(tn / f.sheet.viscosity)));
  }
}

TEST(StabilityLimits, MirrorSymmetry) {
  // theta -> -theta with the fibre angles (and so the rates' D12) mirrored: same growth.
  for (double theta_deg : {10.0, 47.0, 100.0, 161.0}) {
    const TrellisFlow f = build_trellis_flow(spec(20, -55, 0.8, 0.013, -0.007));
    const TrellisFlow m = build_trellis_flow(spec(-20, 55, 0.8, 0.013, -0.007));
    EXPECT_NEAR(m.sheet.rate(0, 1), -f.sheet.rate(0, 1), tol::kExact);
    const double t = theta_deg * kDeg;
    EXPECT_NEAR(fibre_sheet_growth_rate(f.sheet, t), fibre_sheet_growth_rate(m.sheet, -t), tol::kExact);
    const SpectralReport a = solve_spectral(f.sheet, t, 0.7), b = solve_spectral(m.sheet, -t, 0.7);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_NEAR(a.growth_rate, b.growth_rate, 1e-10 * (1 + std::abs(a.growth_rate)));
    // And the Newtonian sheet with mirrored rates.
    const NewtonianGrowthRates ga = newtonian_sheet_growth_rates(f.sheet.rate, 1.0, 1.0, t, 2.0);
    const NewtonianGrowthRates gb = newtonian_sheet_growth_rates(m.sheet.rate, 1.0, 1.0, -t, 2.0);
    EXPECT_NEAR(ga.sinuous, gb.sinuous, tol::kExact * (1 + std::abs(ga.sinuous)));
  }
}

// ---- analysis, input file, outputs ------------------------------------------------

TEST(StabilityAnalysis, MostUnstableModeAndVerdict) {
  const StabilityResult r = analyse_stability(build_trellis_flow(spec(30, -30, 0.5, 0.01, -0.02)), ScanOptions{});
  EXPECT_EQ(r.verdict, Verdict::kBuckles);
  // The exact most unstable direction beats every sampled one.
  double best = -1e300;
  for (const ModeRow& row : r.rows) best = std::max(best, row.growth_rate);
  EXPECT_GE(r.mode.growth_rate, best - tol::kExact);
  EXPECT_LT(r.mode.growth_rate - best, 1e-3 * std::abs(best));
  EXPECT_TRUE(r.check.ok()) << r.check.brief();
  EXPECT_NEAR(r.check.growth_rate, r.check_closed_form, 1e-10 * std::abs(r.check_closed_form));
  const StabilityResult s = analyse_stability(build_trellis_flow(spec(30, -30, 0.5, 0.01, 0.02)), ScanOptions{});
  EXPECT_EQ(s.verdict, Verdict::kStable);
  EXPECT_THAT(s.verdict_line, testing::HasSubstr("stable"));
  const StabilityResult n = analyse_stability(build_trellis_flow(spec(30, -30, 0.5, 0.0, 0.02)), ScanOptions{});
  EXPECT_EQ(n.verdict, Verdict::kNeutral);
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::path(SF_BINARY_DIR) / "test_output" / "stability" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string write_file(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

TEST(StabilityInput, ReadsTheSampleAndReportsPlaces) {
  const StabilityInput in =
      read_stability_input(std::string(SF_SOURCE_DIR) + "/data/forming/stability/pp_glass_45.yaml");
  EXPECT_TRUE(in.has_fibres && in.has_viscosity && in.has_thickness);
  EXPECT_NO_THROW(build_trellis_flow(in.spec));

  const fs::path d = temp_dir("input");
  auto expect_error = [&](const std::string& text, const std::string& pattern) {
    const std::string f = write_file(d / "in.yaml", text);
    try {
      const StabilityInput bad = read_stability_input(f);
      build_trellis_flow(bad.spec);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), testing::ContainsRegex(pattern)) << text;
    }
  };
  const std::string ok = "fibres: [30, -30]\nviscosity: 1.0e-3\nthickness: 2\n";
  expect_error("fibres: [30, -30]\nviscosity: -1.0e-3\nthickness: 2\nshear_rate: 1\ntensions: {T_a: 0, T_b: 0}\n",
               "in\\.yaml:2:12: expected a positive viscosity \\(MPa s\\), found -0\\.001");
  expect_error("fibres: [30, 210]\nviscosity: 1.0e-3\nthickness: 2\nshear_rate: 1\ntensions: {T_a: 0, T_b: 0}\n",
               "in\\.yaml:1:9: the fibre families .*parallel");
  expect_error(ok + "rates: {D11: 1, D22: 1, D12: 0}\ntensions: {T_a: 0, T_b: 0}\n",
               "in\\.yaml:4:8: .*stretches the fibres");
  expect_error(ok + "rates: {D11: 1, D22: -3, D12: 0, D33: 5}\ntensions: {T_a: 0, T_b: 0}\n",
               "in\\.yaml:4:39: D33 = 5 1/s violates incompressibility");
  expect_error(ok + "shear_rate: 1\ntensions: {T_a: 0, T_c: 0}\n",
               "in\\.yaml:5:20: tensions \\(MPa\\): unknown key 'T_c'");
  expect_error(ok + "shear_rate: fast\n",
               "in\\.yaml:4:13: shear_rate \\(1/s\\): expected a finite number, found 'fast'");
  expect_error(ok + "shear_rat: 1\n", "in\\.yaml:4:1: stability input: unknown key 'shear_rat'");
  expect_error("fibres: [30, -30, 5]\n", "in\\.yaml:1:9: fibres .*expected a list of 2 numbers, found a list of 3");
  // A missing key: file, line and column of the mapping it belongs in, and which key.
  expect_error(ok + "shear_rate: 1\ntensions: {T_a: 0}\n",
               "^.*in\\.yaml:5:11: tensions \\(MPa\\): missing required key 'T_b'$");
  expect_error(
      "# comment\n" + ok + "shear_rate: 1\n",
      "^.*in\\.yaml:2:1: key 'tensions': missing: give the fibre tensions T_a, T_b \\(MPa\\) with the rates, or "
      "the tractions \\(.*in\\.yaml:2:1: key 'tractions'\\)$");
  expect_error(ok + "tensions: {T_a: 0, T_b: 0}\n", "^.*in\\.yaml:1:1: key 'rates': missing: give the rates D11");
  const std::string no_viscosity = write_file(d / "in.yaml", "\nfibres: [30, -30]\nthickness: 2\n");
  EXPECT_EQ(read_stability_input(no_viscosity).at, no_viscosity + ":2:1");
}

TEST(StabilityOutput, WritesCsvJsonAndPicturesWithoutADisplay) {
  const fs::path d = temp_dir("outputs");
  ScanOptions scan;
  scan.n_directions = 36;
  scan.n_wavelengths = 5;
  const StabilityResult r = analyse_stability(build_trellis_flow(spec(30, -30, -0.5, 0.01, -0.02)), scan);
  OutputOptions o;
  o.out_dir = (d / "out").string();
  o.quiet = true;
  o.command_line = "test";
  // No display in the environment: the renderer starts its own Xvfb.
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display ? display : "";
  unsetenv("DISPLAY");
  const std::vector<std::string> files = write_stability_outputs(r, o);
  if (!saved.empty()) setenv("DISPLAY", saved.c_str(), 1);
  EXPECT_EQ(files.size(), 5u);
  for (const std::string& f : files) EXPECT_TRUE(fs::exists(d / "out" / f)) << f;

  const io::CsvTable t = io::read_csv((d / "out" / "growth_rate.csv").string());
  EXPECT_EQ(t.n_rows(), 36u * 5u);
  for (const char* c : {"theta_deg", "wavelength", "kappa", "resolved_tension", "growth_rate", "growth_rate_rel"})
    EXPECT_TRUE(t.has_column(c)) << c;
  std::ifstream csv(d / "out" / "growth_rate.csv");
  std::string first, second;
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_THAT(second, testing::HasSubstr("# units: lengths in mm, times in s, stresses in MPa"));

  const nlohmann::json j = nlohmann::json::parse(std::ifstream(d / "out" / "summary.json"));
  EXPECT_EQ(j["verdict"], "buckles");
  EXPECT_EQ(j["background"]["flow"], "thinning");
  EXPECT_LT(j["numerical_check"]["difference_relative"].get<double>(), tol::kFibreSpectralRel);

  // The thinning map shows all three regions: buckling (red), stable (blue), in between.
  const render::RgbImage img = render::read_png_rgb((d / "out" / "stability_map_thinning.png").string());
  EXPECT_EQ(img.width, 1200);
  EXPECT_EQ(img.height, 900);
  int red = 0, blue = 0, orange = 0;
  for (int y = 0; y < img.height; y += 3)
    for (int x = 0; x < img.width; x += 3) {
      const render::Colour c = img.at(x, y);
      if (c.r > 0.85 && c.g < 0.5 && c.b < 0.45) ++red;
      if (c.r < 0.6 && c.g > 0.65 && c.b > 0.85) ++blue;
      if (c.r > 0.95 && c.g > 0.75 && c.g < 0.85 && c.b < 0.55) ++orange;
    }
  EXPECT_GT(red, 1000);
  EXPECT_GT(blue, 1000);
  EXPECT_GT(orange, 100);

  // --no-plots: no pictures, and an existing folder keeps only what is replaced.
  o.plots = false;
  o.out_dir = (d / "noplots").string();
  EXPECT_EQ(write_stability_outputs(r, o).size(), 2u);
  EXPECT_FALSE(fs::exists(d / "noplots" / "stability_map_thinning.png"));
}

}  // namespace
}  // namespace sf::forming::stability
