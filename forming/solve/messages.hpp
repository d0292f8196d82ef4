#pragma once
// Message helpers shared by the forming solvers (static, dynamic, arc length).
#include <sstream>
#include <string>

#include "common/core/error.hpp"

namespace sf::forming::detail {

// A number with 4 significant digits, for residuals and load factors in messages.
inline std::string short_number(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

// Throws sf::InputError "<solver> <option>: expected <expected>, found <found>".
[[noreturn]] inline void bad_solver_option(const std::string& solver, const std::string& option,
                                           const std::string& expected, double found) {
  std::ostringstream os;
  os.precision(10);
  os << solver << " " << option << ": expected " << expected << ", found " << found;
  throw InputError(os.str());
}

}  // namespace sf::forming::detail
