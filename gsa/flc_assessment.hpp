#pragma once
// Forming-limit assessment of the marks (docs/usage.md "Forming-limit assessment",
// docs/theory/strain.md "Forming limit"): curves from a formula, the radial (strain-path)
// margin and the zones of the press shop.
//
// Curves (besides a table, gsa/flc.hpp):
//   Keeler-Brazier (low-carbon steels): FLC0 = (23.3 + 14.13 t) n / 0.21 percent engineering
//     major strain at plane strain, t the sheet thickness in mm (t above 3 mm counts as 3 mm),
//     n the strain-hardening exponent (accepted 0.05..0.35).
//   FLC0 and the standard shape (engineering strain): left of plane strain a 45 degree line
//     e1 = FLC0 - e2 down to the uniaxial line e2 = -e1/2 (minor from -FLC0... to 0),
//     right of it e1 = FLC0 + tan(20 deg) e2 up to minor 0.5. Both are tabulated every
//     0.01 of minor strain and converted to the analysis' measure.
//
// Radial margin: along the ray from the origin through the mark's (minor, major) point (a
// proportional strain path), the distance to the curve minus the mark's distance from the
// origin (strain units; negative beyond the curve; NaN when the ray misses the curve).
//
// Zones, in order of precedence (the first that applies):
//   failure               major strain above the curve (margin < 0)
//   necking_risk          within `necking_margin` below the curve (default 0.10 strain)
//   excess_thinning       thinning (minus thickness change, %) above `thinning_limit_pct` (default 30 %)
//   insufficient_stretch  major strain below `min_stretch` (default 0.02) and minor above -min_stretch
//                         (near the origin: too little deformation, e.g. for dent resistance)
//   compression           minor strain below the pure-shear line (major + minor < 0 in true strain,
//                         lambda1 lambda2 < 1: the sheet thickens; wrinkling tendency)
//   safe                  none of the above, and the mark's minor strain is within the curve's range
//   outside_curve         none of the above, but the curve does not cover the mark's minor strain
//   (empty)               no strain at the mark

#include <array>
#include <map>
#include <string>
#include <vector>

#include "gsa/flc.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

// Keeler-Brazier plane-strain limit FLC0 (engineering major strain, fraction) of a low-carbon
// steel sheet of thickness `thickness_mm` and strain-hardening exponent `n`. Throws
// sf::UsageError naming `n_option` for n outside 0.05..0.35 and `thickness_option` for a
// thickness <= 0.
double keeler_brazier_flc0(double thickness_mm, double n, const std::string& n_option = "--flc-n",
                           const std::string& thickness_option = "--thickness");

// The standard-shape curve through FLC0 (engineering strain, fraction), tabulated and
// converted to `measure`; `source` names it in messages and pictures.
FormingLimitCurve standard_shape_flc(double flc0_engineering, StrainMeasure measure, const std::string& source);

// Distance along the ray through (minor, major) from the origin to the curve; NaN when the
// ray does not meet it or the point is the origin.
double radial_limit(const FormingLimitCurve& curve, double minor, double major);

enum class Zone { kNone, kFailure, kNeckingRisk, kExcessThinning, kInsufficientStretch, kCompression, kSafe, kOutside };
inline constexpr std::array<Zone, 7> kZones = {
    Zone::kFailure,     Zone::kNeckingRisk, Zone::kExcessThinning, Zone::kInsufficientStretch,
    Zone::kCompression, Zone::kSafe,        Zone::kOutside};
// "failure", "necking_risk", ... ("" for kNone): the words of strains.csv and summary.json.
const char* zone_code(Zone z);
// "Failure (above the FLC)", ...: for legends.
std::string zone_label(Zone z);

struct ZoneOptions {
  double necking_margin = 0.10;      // strain below the curve that counts as necking risk (>= 0)
  double thinning_limit_pct = 30.0;  // thinning beyond this many percent is excess thinning (> 0)
  double min_stretch = 0.02;         // major strain below this is insufficient stretch (>= 0)
  // Throws OptionError naming the field ("necking_margin", ...) for a value out of range.
  void validate() const;
};

// The zone of one mark from its strains (in the curve's measure), thickness change (%)
// and the curve's major strain at its minor strain (NaN outside the curve).
Zone classify_zone(double major, double minor, double thickness_change_pct, double limit_major, StrainMeasure measure,
                   const ZoneOptions& options);

struct FlcAssessment {
  std::string curve;    // how the curve was made ("table FILE", "Keeler-Brazier t = .., n = ..", ...)
  std::string strains;  // "mid-surface" or "surface (marked face)"
  ZoneOptions options;
  std::vector<double> radial_margin;    // per mark
  std::vector<Zone> zone;               // per mark
  std::map<std::string, Index> counts;  // zone code -> marks (every zone, 0 included)
};
FlcAssessment assess_marks(const FormingLimitCurve& curve, const MarkStrains& marks,
                           const std::vector<double>& thickness_change_pct, StrainMeasure measure,
                           const ZoneOptions& options);

}  // namespace sf::gsa
