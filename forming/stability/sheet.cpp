#include "forming/stability/sheet.hpp"

#include <cmath>
#include <stdexcept>

namespace sf::forming::stability {

Mat2 SheetState::in_plane_stress() const {
  return 2.0 * viscosity * (rate + rate.trace() * Mat2::Identity()) + fibre_stress();
}

Mat2 SheetState::fibre_stress() const {
  Mat2 m = Mat2::Zero();
  for (const Fibre& f : fibres) m += f.tension * f.direction * f.direction.transpose();
  return m;
}

double SheetState::resolved_tension(const Vec2& n) const { return n.dot(fibre_stress() * n); }

void SheetState::validate(double relative_tolerance) const {
  if (!(viscosity > 0.0) || !std::isfinite(viscosity)) throw std::invalid_argument("SheetState: viscosity must be > 0");
  if (!(thickness > 0.0) || !std::isfinite(thickness)) throw std::invalid_argument("SheetState: thickness must be > 0");
  if (!rate.allFinite() || std::abs(rate(0, 1) - rate(1, 0)) > 1e-12 * (1.0 + rate.norm()))
    throw std::invalid_argument("SheetState: the rate of deformation must be finite and symmetric");
  if (fibres.empty()) return;
  if (fibres.size() != 2) throw std::invalid_argument("SheetState: expected no fibres or two families");
  for (const Fibre& f : fibres) {
    if (std::abs(f.direction.norm() - 1.0) > 1e-12 || !std::isfinite(f.tension))
      throw std::invalid_argument("SheetState: fibre directions must be unit vectors, tensions finite");
    if (std::abs(f.direction.dot(rate * f.direction)) > relative_tolerance * rate.norm())
      throw std::invalid_argument("SheetState: the rate of deformation stretches a fibre family");
  }
  const Vec2& a = fibres[0].direction;
  const Vec2& b = fibres[1].direction;
  if (std::abs(a.x() * b.y() - a.y() * b.x()) < 1e-9)
    throw std::invalid_argument("SheetState: the two fibre families are parallel");
}

Vec2 wave_direction(double theta) { return {std::cos(theta), std::sin(theta)}; }
Vec2 crest_direction(double theta) { return {-std::sin(theta), std::cos(theta)}; }

double fibre_sheet_growth_rate(const SheetState& sheet, double theta) {
  // Section 4: W = -T_n w / mu from the vertical balance of the tilted fibres against the
  // transverse shear of the matrix; G = W / w + D33 from the convected kinematics.
  return sheet.rate33() - sheet.resolved_tension(wave_direction(theta)) / sheet.viscosity;
}

bool normal_to_fibre(const SheetState& sheet, double theta, double tolerance) {
  const Vec2 n = wave_direction(theta);
  for (const Fibre& f : sheet.fibres)
    if (std::abs(n.dot(f.direction)) <= tolerance) return true;
  return false;
}

double sinh_minus_identity(double q) {
  // sinh q - q = q^3/6 (1 + q^2/20 + q^4/840 + q^6/60480 + q^8/6652800 + ...); the series
  // is used below q = 0.1, where the direct difference loses three digits (truncation
  // error there < 1e-18 relative).
  if (q < 0.1) {
    const double q2 = q * q;
    return q * q2 / 6.0 * (1.0 + q2 / 20.0 * (1.0 + q2 / 42.0 * (1.0 + q2 / 72.0 * (1.0 + q2 / 110.0))));
  }
  return std::sinh(q) - q;
}

NewtonianGrowthRates newtonian_sheet_growth_rates(const Mat2& rate, double viscosity, double thickness, double theta,
                                                  double wave_number) {
  const Vec2 n = wave_direction(theta);
  const double s_n = n.dot(2.0 * viscosity * (rate + rate.trace() * Mat2::Identity()) * n);
  const double q = wave_number * thickness;
  const double d33 = -rate.trace();
  NewtonianGrowthRates g;
  g.sinuous = d33 - (s_n / viscosity) * q / (2.0 * sinh_minus_identity(q));
  g.varicose = d33 + (s_n / viscosity) * q / (2.0 * (std::sinh(q) + q));
  return g;
}

double growth_factor(double tau, double fibre_angle_chi, FlowKind kind) {
  const double s = kind == FlowKind::kThickening ? 1.0 : -1.0;
  const double cot = std::abs(std::cos(fibre_angle_chi) / std::sin(fibre_angle_chi));
  return s * (cot < 1e-12 ? 0.0 : cot) - tau;  // chi = 90 deg: exactly 0, not roundoff
}

}  // namespace sf::forming::stability
