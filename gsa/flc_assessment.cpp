#include "gsa/flc_assessment.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/core/error.hpp"
#include "gsa/option_error.hpp"

namespace sf::gsa {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double to_measure(double engineering, StrainMeasure m) { return strain_of_stretch(1.0 + engineering, m); }
}  // namespace

double keeler_brazier_flc0(double t, double n, const std::string& n_option, const std::string& thickness_option) {
  if (!std::isfinite(n) || n < 0.05 || n > 0.35) {
    std::ostringstream s;
    s << n_option << ": the strain-hardening exponent n must be within 0.05..0.35 (Keeler-Brazier, low-carbon "
      << "steels), found " << n;
    throw UsageError(s.str());
  }
  if (!std::isfinite(t) || !(t > 0)) {
    std::ostringstream s;
    s << thickness_option << ": the Keeler-Brazier curve needs the sheet thickness in mm (> 0), found " << t;
    throw UsageError(s.str());
  }
  return (23.3 + 14.13 * std::min(t, 3.0)) * n / 0.21 / 100.0;
}

FormingLimitCurve standard_shape_flc(double flc0, StrainMeasure measure, const std::string& source) {
  if (!std::isfinite(flc0) || !(flc0 > 0) || flc0 > 2.0)
    throw UsageError("--flc0: the plane-strain limit must be a strain in (0, 2], found " + std::to_string(flc0));
  FormingLimitCurve c;
  c.source = source;
  const double slope_right = std::tan(20.0 * kPi / 180.0);
  // Left branch to the uniaxial line e2 = -e1/2: e1 = flc0 - e2 = -2 e2 -> e2 = -flc0.
  const int n_left = static_cast<int>(std::ceil(flc0 / 0.01));
  for (int i = n_left; i >= 1; --i) {
    const double e2 = -flc0 * i / n_left;
    c.minor.push_back(to_measure(e2, measure));
    c.major.push_back(to_measure(flc0 - e2, measure));
  }
  for (int i = 0; i <= 50; ++i) {
    const double e2 = 0.01 * i;
    c.minor.push_back(to_measure(e2, measure));
    c.major.push_back(to_measure(flc0 + slope_right * e2, measure));
  }
  return c;
}

double radial_limit(const FormingLimitCurve& c, double minor, double major) {
  const double r = std::hypot(minor, major);
  if (!(r > 0) || !std::isfinite(r)) return kNaN;
  const Vec2 d(minor / r, major / r);
  double best = kNaN;
  for (std::size_t i = 0; i + 1 < c.minor.size(); ++i) {
    const Vec2 a(c.minor[i], c.major[i]), b(c.minor[i + 1], c.major[i + 1]);
    // t d = a + s (b - a), t > 0, s in [0, 1].
    Mat2 m;
    m << d, a - b;
    const double det = m.determinant();
    if (std::abs(det) < 1e-15) continue;
    const Vec2 ts = m.inverse() * a;
    if (ts[0] > 0 && ts[1] >= -1e-12 && ts[1] <= 1 + 1e-12 && !(best <= ts[0])) best = ts[0];
  }
  return best;
}

const char* zone_code(Zone z) {
  switch (z) {
    case Zone::kFailure:
      return "failure";
    case Zone::kNeckingRisk:
      return "necking_risk";
    case Zone::kExcessThinning:
      return "excess_thinning";
    case Zone::kCompression:
      return "compression";
    case Zone::kInsufficientStretch:
      return "insufficient_stretch";
    case Zone::kSafe:
      return "safe";
    case Zone::kOutside:
      return "outside_curve";
    case Zone::kNone:
      break;
  }
  return "";
}

std::string zone_label(Zone z) {
  switch (z) {
    case Zone::kFailure:
      return "failure (above the FLC)";
    case Zone::kNeckingRisk:
      return "necking risk (near the FLC)";
    case Zone::kExcessThinning:
      return "excess thinning";
    case Zone::kCompression:
      return "compression / wrinkling tendency";
    case Zone::kInsufficientStretch:
      return "insufficient stretch";
    case Zone::kSafe:
      return "safe";
    case Zone::kOutside:
      return "outside the curve's minor range";
    case Zone::kNone:
      break;
  }
  return "no strain";
}

void ZoneOptions::validate() const {
  if (!std::isfinite(necking_margin) || necking_margin < 0)
    throw OptionError("necking_margin", "expected a strain >= 0, found " + std::to_string(necking_margin));
  if (!std::isfinite(thinning_limit_pct) || !(thinning_limit_pct > 0) || thinning_limit_pct >= 100)
    throw OptionError("thinning_limit_pct",
                      "expected a percentage in (0, 100), found " + std::to_string(thinning_limit_pct));
  if (!std::isfinite(min_stretch) || min_stretch < 0)
    throw OptionError("min_stretch", "expected a strain >= 0, found " + std::to_string(min_stretch));
}

Zone classify_zone(double major, double minor, double thick_pct, double limit, StrainMeasure measure,
                   const ZoneOptions& o) {
  if (!std::isfinite(major) || !std::isfinite(minor)) return Zone::kNone;
  if (std::isfinite(limit)) {
    const double margin = limit - major;
    if (margin < 0) return Zone::kFailure;
    if (margin < o.necking_margin) return Zone::kNeckingRisk;
  }
  if (std::isfinite(thick_pct) && -thick_pct > o.thinning_limit_pct) return Zone::kExcessThinning;
  // Below the pure-shear line: the area shrinks (lambda1 lambda2 < 1), whatever the measure.
  const double l1 = measure == StrainMeasure::kTrue          ? std::exp(major)
                    : measure == StrainMeasure::kEngineering ? 1.0 + major
                                                             : std::sqrt(std::max(0.0, 1.0 + 2.0 * major));
  const double l2 = measure == StrainMeasure::kTrue          ? std::exp(minor)
                    : measure == StrainMeasure::kEngineering ? 1.0 + minor
                                                             : std::sqrt(std::max(0.0, 1.0 + 2.0 * minor));
  if (major < o.min_stretch && minor > -o.min_stretch) return Zone::kInsufficientStretch;
  if (l1 * l2 < 1.0) return Zone::kCompression;
  return std::isfinite(limit) ? Zone::kSafe : Zone::kOutside;
}

FlcAssessment assess_marks(const FormingLimitCurve& curve, const MarkStrains& marks, const std::vector<double>& thick,
                           StrainMeasure measure, const ZoneOptions& o) {
  FlcAssessment a;
  a.options = o;
  for (Zone z : kZones) a.counts[zone_code(z)] = 0;
  const std::size_t n = marks.major.size();
  a.radial_margin.assign(n, kNaN);
  a.zone.assign(n, Zone::kNone);
  for (std::size_t i = 0; i < n; ++i) {
    const double M = marks.major[i], m = marks.minor[i];
    if (!std::isfinite(M) || !std::isfinite(m)) continue;
    const double lim = radial_limit(curve, m, M);
    if (std::isfinite(lim)) a.radial_margin[i] = lim - std::hypot(m, M);
    a.zone[i] = classify_zone(M, m, i < thick.size() ? thick[i] : kNaN, curve.major_at(m), measure, o);
    ++a.counts[zone_code(a.zone[i])];
  }
  return a;
}

}  // namespace sf::gsa
