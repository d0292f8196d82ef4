#include "forming/stability/analysis.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sf::forming::stability {
namespace {

constexpr double kDeg = kPi / 180.0;

double wrap_180(double deg) {
  double d = std::fmod(deg, 180.0);
  if (d < 0.0) d += 180.0;
  if (d >= 180.0 - 1e-12) d = 0.0;
  return d;
}

}  // namespace

void ScanOptions::validate() const {
  if (min_wavelength < 0.0 || max_wavelength < 0.0 ||
      (min_wavelength > 0.0 && max_wavelength > 0.0 && !(max_wavelength > min_wavelength)))
    throw std::invalid_argument("ScanOptions: wavelengths must be >= 0 with max > min");
  if (n_wavelengths < 2 || n_directions < 4) throw std::invalid_argument("ScanOptions: too few samples");
  if (spectral_degree < 2 || spectral_degree > 29) throw std::invalid_argument("ScanOptions: spectral degree");
}

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::kStable:
      return "stable";
    case Verdict::kNeutral:
      return "neutral";
    case Verdict::kBuckles:
      return "buckles";
  }
  return "?";
}

StabilityMap stability_map(FlowKind kind, double fibre_angle, double log10_kappa_lo, double log10_kappa_hi,
                           double tau_lo, double tau_hi, int n_kappa, int n_tau) {
  StabilityMap m;
  m.kind = kind;
  m.fibre_angle = fibre_angle;
  for (int i = 0; i < n_kappa; ++i)
    m.log10_kappa.push_back(log10_kappa_lo + (log10_kappa_hi - log10_kappa_lo) * i / (n_kappa - 1));
  for (int j = 0; j < n_tau; ++j) m.tau.push_back(tau_lo + (tau_hi - tau_lo) * j / (n_tau - 1));
  for (int j = 0; j < n_tau; ++j)
    for (int i = 0; i < n_kappa; ++i) m.growth.push_back(growth_factor(m.tau[j], fibre_angle, kind));
  m.boundary_tau = growth_factor(0.0, fibre_angle, kind);  // Gamma = boundary - tau
  return m;
}

StabilityResult analyse_stability(const TrellisFlow& flow, const ScanOptions& scan) {
  scan.validate();
  StabilityResult r;
  r.flow = flow;
  r.scan = scan;
  const SheetState& s = flow.sheet;
  const double h = s.thickness;
  r.scan.min_wavelength = scan.min_wavelength > 0.0 ? scan.min_wavelength : 0.5 * h;
  r.scan.max_wavelength = scan.max_wavelength > 0.0 ? scan.max_wavelength : 200.0 * h;
  if (!(r.scan.max_wavelength > r.scan.min_wavelength))
    throw std::invalid_argument("analyse_stability: max wavelength must exceed the min");

  // ---- growth rate over direction and wavelength
  const double l0 = std::log(r.scan.min_wavelength), l1 = std::log(r.scan.max_wavelength);
  for (int d = 0; d < scan.n_directions; ++d) {
    const double theta_deg = 180.0 * d / scan.n_directions;
    const double theta = theta_deg * kDeg;
    const double g = fibre_sheet_growth_rate(s, theta);
    const bool exceptional = normal_to_fibre(s, theta);
    for (int w = 0; w < scan.n_wavelengths; ++w) {
      ModeRow row;
      row.theta_deg = theta_deg;
      row.crest_deg = wrap_180(theta_deg + 90.0);
      row.wavelength = std::exp(l0 + (l1 - l0) * w / (scan.n_wavelengths - 1));
      row.wave_number = 2.0 * kPi / row.wavelength;
      row.kappa = std::pow(row.wave_number * h, 2);
      row.resolved_tension = s.resolved_tension(wave_direction(theta));
      row.growth_rate = g;
      row.growth_rate_rel = g - s.rate33();
      row.newtonian_sinuous = newtonian_sheet_growth_rates(s.rate, s.viscosity, h, theta, row.wave_number).sinuous;
      row.normal_to_fibre = exceptional;
      r.rows.push_back(row);
    }
  }

  // ---- most unstable mode: T_n = n.M.n is smallest along M's eigenvector of the smaller
  // eigenvalue (exact, not the sampled maximum).
  const Eigen::SelfAdjointEigenSolver<Mat2> es(s.fibre_stress());
  const Vec2 n = es.eigenvectors().col(0);
  MostUnstableMode& m = r.mode;
  m.theta_deg = wrap_180(std::atan2(n.y(), n.x()) / kDeg);
  m.crest_deg = wrap_180(m.theta_deg + 90.0);
  m.resolved_tension = es.eigenvalues()(0);
  m.growth_rate = fibre_sheet_growth_rate(s, m.theta_deg * kDeg);
  m.growth_rate_rel = m.growth_rate - s.rate33();
  m.tau = flow.shear_rate != 0.0 ? m.resolved_tension / (s.viscosity * std::abs(flow.shear_rate))
                                 : std::numeric_limits<double>::quiet_NaN();
  m.normal_to_fibre = normal_to_fibre(s, m.theta_deg * kDeg);

  // ---- verdict (relative to the thickness: the sign of the smallest resolved tension)
  const double scale = std::max(std::abs(s.fibres[0].tension), std::abs(s.fibres[1].tension));
  const double tol = 1e-9 * scale;
  r.verdict = m.resolved_tension < -tol  ? Verdict::kBuckles
              : m.resolved_tension > tol ? Verdict::kStable
                                         : Verdict::kNeutral;
  const std::string where = fmt::format("wave direction {:.1f} deg, crests along {:.1f} deg", m.theta_deg, m.crest_deg);
  switch (r.verdict) {
    case Verdict::kBuckles:
      r.verdict_line = fmt::format(
          "verdict: UNSTABLE, the laminate buckles out of plane: the fibre tension resolved across the crests ({}) "
          "is {:.4g} MPa < 0; keep both fibre families in tension",
          where, m.resolved_tension);
      break;
    case Verdict::kStable:
      r.verdict_line = fmt::format(
          "verdict: stable: the fibre tension resolved in every direction is positive (smallest {:.4g} MPa, {}); "
          "out-of-plane buckles shrink relative to the thickness",
          m.resolved_tension, where);
      break;
    case Verdict::kNeutral:
      r.verdict_line = fmt::format(
          "verdict: neutral: a fibre family is slack (smallest resolved tension 0 MPa, {}); buckles neither grow nor "
          "shrink relative to the thickness; any compression makes the laminate buckle",
          where);
      break;
  }
  r.mode_line = fmt::format(
      "most unstable mode: {}; every wavelength alike (the growth rate does not depend on wavelength for a sheet "
      "reinforced through its thickness); growth rate G = {:.4g} 1/s, relative to the thickness G - D33 = {:.4g} 1/s "
      "({} flow, D33 = {:.4g} 1/s){}",
      where, m.growth_rate, m.growth_rate_rel, flow_kind_name(flow), s.rate33(),
      m.normal_to_fibre ? "; the crests run along a fibre family, so the buckle also excites shear along them: G is "
                          "its instantaneous rate, and neighbouring directions (normal modes) have nearly the same G"
                        : "");

  // ---- maps: the scanned kappa range; tau wide enough for the boundaries and the laminate
  const double k_lo = std::pow(2.0 * kPi * h / r.scan.max_wavelength, 2);
  const double k_hi = std::pow(2.0 * kPi * h / r.scan.min_wavelength, 2);
  const double cot = std::abs(std::cos(flow.fibre_angle) / std::sin(flow.fibre_angle));
  double t_max = std::max(2.0, 2.0 * cot + 1.0);
  if (std::isfinite(m.tau)) t_max = std::max(t_max, 1.25 * std::abs(m.tau));
  constexpr int kMapKappa = 24, kMapTau = 56;
  r.thickening_map = stability_map(FlowKind::kThickening, flow.fibre_angle, std::log10(k_lo), std::log10(k_hi), -t_max,
                                   t_max, kMapKappa, kMapTau);
  r.thinning_map = stability_map(FlowKind::kThinning, flow.fibre_angle, std::log10(k_lo), std::log10(k_hi), -t_max,
                                 t_max, kMapKappa, kMapTau);

  // ---- independent numerical check at the most unstable direction, middle wavelength
  r.check_wave_number = 2.0 * kPi / std::sqrt(r.scan.min_wavelength * r.scan.max_wavelength);
  r.check_closed_form = m.growth_rate;
  SpectralOptions so;
  so.degree = scan.spectral_degree;
  r.check = solve_spectral(s, m.theta_deg * kDeg, r.check_wave_number, so);
  for (const Fibre& f : s.fibres) {
    StabilityResult::Exceptional e;
    e.theta_deg = wrap_180(std::atan2(f.direction.y(), f.direction.x()) / kDeg + 90.0);
    e.closed_form_limit = fibre_sheet_growth_rate(s, e.theta_deg * kDeg);
    e.instantaneous = solve_spectral(s, e.theta_deg * kDeg, r.check_wave_number, so).buckle_growth_rate;
    r.exceptional.push_back(e);
  }
  return r;
}

}  // namespace sf::forming::stability
