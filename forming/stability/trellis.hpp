#pragma once
// The background trellis flow of a bidirectional laminate, built from what a forming engineer
// knows: the two fibre angles, the viscosity and thickness, and either
//   (a) the in-plane rates of deformation (or the trellis shear rate) and the fibre tensions, or
//   (b) the in-plane stress (boundary tractions, through-thickness mean), which determine the
//       trellis shear rate and both tensions.
// Bad input is an sf::InputError whose message starts with where the value came from (an
// option such as "--rates" or "FILE:LINE:COLUMN" of a YAML key), says what was expected and
// what was found.
//
// Consistency of the background (docs/theory/stability.md, section 2): both fibre families
// inextensible, a.D.a = b.D.b = 0, leaves one rate parameter in the plane,
//   D = r (a_perp (x) b_perp + b_perp (x) a_perp),
// and D33 = -(D11 + D22). Given rates must satisfy both to kRateTolerance (relative to |D|);
// rates within it are projected onto the trellis family (the change is reported).
//
// Angles in degrees from x1 towards x2. Units as in sheet.hpp (mm, s, MPa in the samples).

#include <array>
#include <optional>
#include <string>

#include "forming/stability/sheet.hpp"

namespace sf::forming::stability {

// Rates off the trellis family by more than this fraction of |D| (Frobenius) are rejected.
inline constexpr double kRateTolerance = 1e-3;
// The two families must be at least this far from parallel (degrees).
inline constexpr double kMinFibreAngleDeg = 1.0;

struct TrellisSpec {
  // Each value with the place it came from, for messages ("--viscosity", "in.yaml:4:12").
  std::array<double, 2> fibre_angles_deg{0.0, 0.0};  // families a and b, degrees from x1
  std::string fibres_at = "--fibres";
  double viscosity = 0.0;  // mu, MPa s
  std::string viscosity_at = "--viscosity";
  double thickness = 0.0;  // h, mm
  std::string thickness_at = "--thickness";

  std::optional<std::array<double, 3>> rates;  // D11, D22, D12, 1/s
  std::string rates_at = "--rates";
  std::optional<double> rate33;  // D33, 1/s (optional; checked against -(D11 + D22))
  std::string rate33_at = "--rate33";
  std::optional<double> shear_rate;  // gamma_dot = -d(chi)/dt, 1/s (instead of rates)
  std::string shear_rate_at = "--shear-rate";
  std::optional<std::array<double, 2>> tensions;  // T_a, T_b, MPa
  std::string tensions_at = "--tensions";
  std::optional<std::array<double, 3>> tractions;  // sigma11, sigma22, sigma12, MPa
  std::string tractions_at = "--tractions";
};

struct TrellisFlow {
  enum class Source { kRatesAndTensions, kShearRateAndTensions, kTractions };

  SheetState sheet;                          // two families: [0] = a, [1] = b
  std::array<double, 2> fibre_angles_deg{};  // as given
  double fibre_angle = 0.0;                  // chi in (0, pi): angle between the families, rad
  double bisector_deg = 0.0;                 // direction of a + b (inside chi), degrees from x1
  double shear_rate = 0.0;                   // gamma_dot = -d(chi)/dt, 1/s
  Source source = Source::kRatesAndTensions;
  double projection = 0.0;  // |D_given - D_used| / |D_given| (0 unless rates were given)

  // D33 > 0: the sheet thickens; D33 < 0: it thins (D33 = gamma_dot cot chi). |D33| below
  // 1e-12 |D| (roundoff, e.g. at chi = 90 deg) counts as neither.
  bool thickening() const { return sheet.rate33() > 1e-12 * sheet.rate.norm(); }
  bool thinning() const { return sheet.rate33() < -1e-12 * sheet.rate.norm(); }
};

// Checks the specification and builds the flow. Throws sf::InputError (see above).
TrellisFlow build_trellis_flow(const TrellisSpec& spec);

// The unit trellis rate for families a, b: a_perp (x) b_perp + b_perp (x) a_perp, scaled so
// that its trellis shear rate gamma_dot is 1 (a and b unit, not parallel).
Mat2 unit_trellis_rate(const Vec2& a, const Vec2& b);
// gamma_dot = 2 a.D.b / sin(chi), the rate at which the angle between the families closes.
double trellis_shear_rate(const Mat2& rate, const Vec2& a, const Vec2& b);

// For messages: "thickening", "thinning" or "neither thickening nor thinning".
std::string flow_kind_name(const TrellisFlow& flow);

}  // namespace sf::forming::stability
