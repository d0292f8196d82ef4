#pragma once
// Ramps: how a prescribed displacement or a load grows with the load factor (or with the
// time t / end_time of a dynamic run).
//   kLinear  r(t) = t
//   kSmooth  r(t) = 3 t^2 - 2 t^3   (zero rate at both ends)
//   kConstant r(t) = 1 for t > 0, r(0) = 0 (full value from the first step on, e.g. the
//            vacuum that holds a laminate between diaphragms before it is formed)
// t is clamped to [0, 1]; r(0) = 0, r(1) = 1.
#include <string>

namespace sf::forming {

enum class Ramp { kLinear, kSmooth, kConstant };

// "linear", "smooth", "constant" (the case-file names).
std::string to_string(Ramp ramp);
double ramp_value(Ramp ramp, double t);
// dr/dt (0 outside [0, 1]; the linear ramp's rate is 1 on the whole closed interval).
double ramp_rate(Ramp ramp, double t);

}  // namespace sf::forming
