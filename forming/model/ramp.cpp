#include "forming/model/ramp.hpp"

#include <algorithm>

namespace sf::forming {

std::string to_string(Ramp ramp) {
  return ramp == Ramp::kLinear ? "linear" : ramp == Ramp::kSmooth ? "smooth" : "constant";
}

double ramp_value(Ramp ramp, double t) {
  if (ramp == Ramp::kConstant) return t > 0.0 ? 1.0 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return ramp == Ramp::kLinear ? t : t * t * (3.0 - 2.0 * t);
}

double ramp_rate(Ramp ramp, double t) {
  if (t < 0.0 || t > 1.0 || ramp == Ramp::kConstant) return 0.0;
  return ramp == Ramp::kLinear ? 1.0 : 6.0 * t * (1.0 - t);
}

}  // namespace sf::forming
