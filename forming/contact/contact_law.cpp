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

// The released tail's energy per S_t at s = (d - L) / L in [0, 1] of the taper (d the
// parting beyond the open end, L = R / 2): L^2 / 2 + integral from L to d of d' h(d') dd'.
double tail_release_energy(double L, double s) {
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s;
  return 0.5 * L * L + L * (L * (s - s3 + 0.5 * s4) + L * (0.5 * s2 - 0.75 * s4 + 0.4 * s4 * s));
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
  if (!(std::isfinite(tail_release) && tail_release >= 0.0))
    bad("normal tail release", "a length >= 0 (mm) over which the linear tail's tie falls to nothing", tail_release);
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
      // Linear; released (contact_law.hpp): the tie S_t d tapers to nothing over the
      // second half of the parting d in [R / 2, R] by h(s) = 1 - 3 s^2 + 2 s^3.
      const double R = law.tail_release;
      const double d = -x;
      if (R > 0.0 && d > 0.5 * R) {
        const double L = 0.5 * R;
        const double s1 = std::min((d - L) / L, 1.0);
        const double h = 1.0 - s1 * s1 * (3.0 - 2.0 * s1);
        const double dh = -6.0 * s1 * (1.0 - s1) / L;  // dh/dd
        r.pressure -= st * d * h;
        r.stiffness += st * (h + d * dh);
        r.energy += st * (tail_release_energy(L, s1) - tail_release_energy(L, 1.0));
      } else {
        r.pressure += st * x;
        r.stiffness += st;
        r.energy += 0.5 * st * x * x;
        if (R > 0.0) r.energy -= st * tail_release_energy(0.5 * R, 1.0);
      }
    }
  }
  return r;
}

}  // namespace sf::forming
