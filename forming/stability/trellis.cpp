#include "forming/stability/trellis.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "common/core/error.hpp"

namespace sf::forming::stability {
namespace {

constexpr double kDeg = kPi / 180.0;

Vec2 unit_at(double deg) { return {std::cos(deg * kDeg), std::sin(deg * kDeg)}; }
Vec2 perp(const Vec2& v) { return {-v.y(), v.x()}; }

[[noreturn]] void bad(const std::string& where, const std::string& message) {
  throw InputError(where + ": " + message);
}

// Shortest round-trip-ish text for messages.
std::string num(double v) { return fmt::format("{:.6g}", v); }

void check_positive(double v, const std::string& where, const std::string& what, const std::string& unit) {
  if (!std::isfinite(v) || !(v > 0.0)) bad(where, "expected a positive " + what + " (" + unit + "), found " + num(v));
}

void check_finite(const double* v, int n, const std::string& where, const std::string& what) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) bad(where, "expected finite " + what + ", found " + num(v[i]));
}

}  // namespace

Mat2 unit_trellis_rate(const Vec2& a, const Vec2& b) {
  const Mat2 d = perp(a) * perp(b).transpose() + perp(b) * perp(a).transpose();
  return d / trellis_shear_rate(d, a, b);
}

double trellis_shear_rate(const Mat2& rate, const Vec2& a, const Vec2& b) {
  // d(a.b)/dt = 2 a.D.b for material directions of inextensible fibres (spin drops out);
  // a.b = cos chi, so d(chi)/dt = -2 a.D.b / sin chi.
  const double sin_chi = std::abs(a.x() * b.y() - a.y() * b.x());
  return 2.0 * a.dot(rate * b) / sin_chi;
}

std::string flow_kind_name(const TrellisFlow& flow) {
  if (flow.thickening()) return "thickening";
  if (flow.thinning()) return "thinning";
  return "neither thickening nor thinning";
}

TrellisFlow build_trellis_flow(const TrellisSpec& spec) {
  TrellisFlow flow;

  // ---- fibres
  check_finite(spec.fibre_angles_deg.data(), 2, spec.fibres_at, "fibre angles (degrees)");
  const Vec2 a = unit_at(spec.fibre_angles_deg[0]);
  const Vec2 b = unit_at(spec.fibre_angles_deg[1]);
  const double sin_chi = std::abs(a.x() * b.y() - a.y() * b.x());
  if (sin_chi < std::sin(kMinFibreAngleDeg * kDeg))
    bad(spec.fibres_at,
        "the fibre families at " + num(spec.fibre_angles_deg[0]) + " and " + num(spec.fibre_angles_deg[1]) +
            " deg are parallel (a degenerate pair: " + num(std::asin(std::min(1.0, sin_chi)) / kDeg) +
            " deg apart); a trellis flow needs two families at least " + num(kMinFibreAngleDeg) + " deg from parallel");
  flow.fibre_angles_deg = spec.fibre_angles_deg;
  flow.fibre_angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
  const Vec2 bis = (a + b).normalized();
  flow.bisector_deg = std::atan2(bis.y(), bis.x()) / kDeg;

  // ---- material and geometry
  check_positive(spec.viscosity, spec.viscosity_at, "viscosity", "MPa s");
  check_positive(spec.thickness, spec.thickness_at, "thickness", "mm");
  SheetState& s = flow.sheet;
  s.viscosity = spec.viscosity;
  s.thickness = spec.thickness;
  s.fibres = {Fibre{a, 0.0}, Fibre{b, 0.0}};

  // ---- which description of the state
  const bool kin = spec.rates.has_value() || spec.shear_rate.has_value();
  if (spec.rates && spec.shear_rate)
    bad(spec.shear_rate_at, "give either the rates (" + spec.rates_at + ") or the trellis shear rate, not both");
  if (spec.rate33 && !spec.rates)
    bad(spec.rate33_at, "D33 is checked against the in-plane rates; give them too (" + spec.rates_at + ")");
  if (spec.tractions) {
    if (spec.tensions)
      bad(spec.tractions_at,
          "give either the fibre tensions (" + spec.tensions_at + ") or the tractions that determine them, not both");
    if (kin)
      bad(spec.tractions_at, "the tractions determine the trellis rate as well; leave out " +
                                 (spec.rates ? spec.rates_at : spec.shear_rate_at));
  } else {
    if (!spec.tensions)
      bad(spec.tensions_at, "missing: give the fibre tensions T_a, T_b (MPa) with the rates, or the tractions (" +
                                spec.tractions_at + ")");
    if (!kin)
      bad(spec.rates_at, "missing: give the rates D11, D22, D12 (1/s) or the trellis shear rate (" +
                             spec.shear_rate_at + ") with the fibre tensions");
  }

  const Mat2 unit = unit_trellis_rate(a, b);
  if (spec.tractions) {
    // sigma_par = 2 mu gamma_dot (U + tr(U) I) + T_a a(x)a + T_b b(x)b, three equations
    // (11, 22, 12) for gamma_dot, T_a, T_b; the matrix is regular for non-parallel families.
    const std::array<double, 3>& t = *spec.tractions;
    check_finite(t.data(), 3, spec.tractions_at, "tractions (MPa)");
    const Mat2 r = 2.0 * spec.viscosity * (unit + unit.trace() * Mat2::Identity());
    Eigen::Matrix3d m;
    m << r(0, 0), a.x() * a.x(), b.x() * b.x(),  //
        r(1, 1), a.y() * a.y(), b.y() * b.y(),   //
        r(0, 1), a.x() * a.y(), b.x() * b.y();
    const Eigen::Vector3d x = m.fullPivLu().solve(Eigen::Vector3d(t[0], t[1], t[2]));
    flow.shear_rate = x(0);
    s.rate = x(0) * unit;
    s.fibres[0].tension = x(1);
    s.fibres[1].tension = x(2);
    flow.source = TrellisFlow::Source::kTractions;
    return flow;
  }

  const std::array<double, 2>& tt = *spec.tensions;
  check_finite(tt.data(), 2, spec.tensions_at, "fibre tensions (MPa)");
  s.fibres[0].tension = tt[0];
  s.fibres[1].tension = tt[1];

  if (spec.shear_rate) {
    check_finite(&*spec.shear_rate, 1, spec.shear_rate_at, "trellis shear rate (1/s)");
    flow.shear_rate = *spec.shear_rate;
    s.rate = flow.shear_rate * unit;
    flow.source = TrellisFlow::Source::kShearRateAndTensions;
    return flow;
  }

  const std::array<double, 3>& d = *spec.rates;
  check_finite(d.data(), 3, spec.rates_at, "rates of deformation (1/s)");
  Mat2 given;
  given << d[0], d[2], d[2], d[1];
  const double size = given.norm();
  if (spec.rate33) {
    check_finite(&*spec.rate33, 1, spec.rate33_at, "D33 (1/s)");
    const double expect = -(d[0] + d[1]);
    if (std::abs(*spec.rate33 - expect) > kRateTolerance * std::max(size, std::abs(*spec.rate33)))
      bad(spec.rate33_at, "D33 = " + num(*spec.rate33) + " 1/s violates incompressibility: with D11 = " + num(d[0]) +
                              " and D22 = " + num(d[1]) + " it must be -(D11 + D22) = " + num(expect) + " 1/s");
  }
  const double stretch_a = a.dot(given * a);
  const double stretch_b = b.dot(given * b);
  if (std::max(std::abs(stretch_a), std::abs(stretch_b)) > kRateTolerance * size) {
    // The trellis rate nearest to the given one (Frobenius), as a suggestion.
    const double g = (given.cwiseProduct(unit)).sum() / unit.squaredNorm();
    const Mat2 near = g * unit;
    bad(spec.rates_at, "(D11, D22, D12) = (" + num(d[0]) + ", " + num(d[1]) + ", " + num(d[2]) +
                           ") 1/s stretches the fibres (a.D.a = " + num(stretch_a) + ", b.D.b = " + num(stretch_b) +
                           " 1/s), but inextensible fibres at " + num(spec.fibre_angles_deg[0]) + " and " +
                           num(spec.fibre_angles_deg[1]) + " deg allow only trellis rates, multiples of (" +
                           num(unit(0, 0)) + ", " + num(unit(1, 1)) + ", " + num(unit(0, 1)) + "); the nearest is (" +
                           num(near(0, 0)) + ", " + num(near(1, 1)) + ", " + num(near(0, 1)) + ")");
  }
  // Within tolerance: the nearest trellis rate (Frobenius projection onto the family).
  flow.shear_rate = (given.cwiseProduct(unit)).sum() / unit.squaredNorm();
  s.rate = flow.shear_rate * unit;
  flow.projection = size > 0.0 ? (given - s.rate).norm() / size : 0.0;
  flow.source = TrellisFlow::Source::kRatesAndTensions;
  return flow;
}

}  // namespace sf::forming::stability
