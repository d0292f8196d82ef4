#include "forming/contact/contact_law.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

[[noreturn]] void bad(const std::string& field, const std::string& expected, double found) {
  std::ostringstream os;
  os.precision(10);
  os << "contact " << field << ": expected " << expected << ", found " << found;
  throw InputError(os.str());
}

}  // namespace

void NormalLaw::validate() const {
  if (!(std::isfinite(stiffness) && stiffness > 0.0)) bad("normal stiffness", "a positive S_n (N/mm^3)", stiffness);
  if (augmented && !(std::isfinite(tolerance) && tolerance > 0.0))
    bad("normal tolerance", "a positive penetration (mm) for the augmented Lagrangian", tolerance);
  if (!(std::isfinite(tail) && tail >= 0.0)) bad("normal tail", "a tail stiffness S_t >= 0 (N/mm^3)", tail);
  if (augmented && tail > 0.0)
    bad("normal tail", "no tail with the augmented Lagrangian (its multiplier is the bearing pressure alone)", tail);
  if (!(std::isfinite(tail_reach) && tail_reach >= 0.0)) bad("normal tail_reach", "a length >= 0 (mm)", tail_reach);
}

void FrictionLaw::validate() const {
  if (!(std::isfinite(viscous) && viscous >= 0.0)) bad("friction viscous", "c_f >= 0 (N s/mm^3)", viscous);
  if (!(std::isfinite(coulomb) && coulomb >= 0.0)) bad("friction coulomb", "mu >= 0", coulomb);
  if (!(std::isfinite(stick_slip) && stick_slip >= 0.0))
    bad("friction stick_slip", "a slip distance >= 0 (mm) up to which Coulomb friction sticks elastically", stick_slip);
  if (stick_slip > 0.0 && stick_velocity > 0.0)
    bad("friction stick_slip", "either stick_slip or stick_velocity, not both (stick_velocity given)", stick_slip);
  if (coulomb > 0.0 && stick_slip == 0.0 && !(std::isfinite(stick_velocity) && stick_velocity > 0.0))
    bad("friction stick_velocity", "a positive slip rate (mm/s) below which Coulomb friction sticks", stick_velocity);
  if (!std::isfinite(engage_gap)) bad("friction engage_gap", "a finite gap (mm)", engage_gap);
}

std::string FrictionLaw::describe() const {
  std::ostringstream os;
  if (!active()) return "frictionless";
  if (viscous > 0.0) os << "viscous c_f = " << viscous << " N s/mm^3";
  if (viscous > 0.0 && coulomb > 0.0) os << " + ";
  if (coulomb > 0.0 && stick_slip > 0.0)
    os << "Coulomb mu = " << coulomb << " (elastic stick up to " << stick_slip << " mm of slip)";
  else if (coulomb > 0.0)
    os << "Coulomb mu = " << coulomb << " (stick below " << stick_velocity << " mm/s)";
  return os.str();
}

NormalResponse normal_response(const NormalLaw& law, double gap, double lambda, double band) {
  NormalResponse r;
  const double s = law.stiffness;
  const double t = lambda - s * gap;  // the trial pressure
  const double b = s * band;          // the band in pressure units
  if (t >= 0.5 * b) {
    r.pressure = t;
    r.energy = (t * t / 2.0 + b * b / 24.0) / s;
    r.stiffness = s;
  } else if (t > -0.5 * b) {
    const double u = t + 0.5 * b;
    r.pressure = u * u / (2.0 * b);
    r.energy = u * u * u / (6.0 * b * s);
    r.stiffness = s * u / b;
  }
  r.bearing = r.pressure;
  r.bearing_stiffness = r.stiffness;
  if (law.tail > 0.0) {
    const double x = (t + 0.5 * b) / s;  // mm inside the open end
    const double st = law.tail;
    const double reach = law.tail_reach;
    if (reach > 0.0) {
      const double y = x / reach;
      const double th = std::tanh(y);
      const double ay = std::abs(y);
      r.pressure += st * reach * th;
      r.stiffness += st * (1.0 - th * th);
      // log cosh y = |y| + log(1 + e^(-2|y|)) - log 2, without overflow.
      r.energy += st * reach * reach * (ay + std::log1p(std::exp(-2.0 * ay)) - std::log(2.0));
    } else {
      r.pressure += st * x;
      r.stiffness += st;
      r.energy += 0.5 * st * x * x;
    }
  }
  return r;
}

}  // namespace sf::forming
