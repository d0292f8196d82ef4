#include "forming/model/ramp.hpp"

#include <algorithm>

namespace sf::forming {

std::string to_string(Ramp ramp) { return ramp == Ramp::kLinear ? "linear" : "smooth"; }

double ramp_value(Ramp ramp, double t) {
  t = std::clamp(t, 0.0, 1.0);
  return ramp == Ramp::kLinear ? t : t * t * (3.0 - 2.0 * t);
}

double ramp_rate(Ramp ramp, double t) {
  if (t < 0.0 || t > 1.0) return 0.0;
  return ramp == Ramp::kLinear ? 1.0 : 6.0 * t * (1.0 - t);
}

}  // namespace sf::forming
