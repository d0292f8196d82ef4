#pragma once
// The analytic deformation behind the example exports in data/formats/
// (make_examples.py there): a 7 x 7 grid 5 mm apart, stretched 1.10 x 0.95 and moved
// rigidly; the stage series scales it with the stage time t (s, 0 to 10).

#include <cmath>
#include <string>

#include "common/core/types.hpp"

namespace sf::test {

inline std::string formats_dir() { return std::string(SF_SOURCE_DIR) + "/data/formats/"; }

// Reference position of grid row i (along Y), column j (along X).
inline Vec3 example_reference(int i, int j) { return Vec3((j - 3) * 5.0, (i - 3) * 5.0, 0.0); }

// Current position at stage time t of the point with reference position X.
inline Vec3 example_current(const Vec3& X, double t = 10.0) {
  const double s = t / 10.0;
  const double l1 = 1.0 + 0.010 * t, l2 = 1.0 - 0.005 * t;
  const double a = 20.0 * s * M_PI / 180.0, b = 10.0 * s * M_PI / 180.0;
  const Vec3 stretched(l1 * X.x(), l2 * X.y(), X.z());
  const Vec3 about_z(std::cos(a) * stretched.x() - std::sin(a) * stretched.y(),
                     std::sin(a) * stretched.x() + std::cos(a) * stretched.y(), stretched.z());
  const Vec3 about_x(about_z.x(), std::cos(b) * about_z.y() - std::sin(b) * about_z.z(),
                     std::sin(b) * about_z.y() + std::cos(b) * about_z.z());
  return about_x + Vec3(2.0 * s, -1.0 * s, 3.0 * s);
}

// Exact strains of the full deformation (t = 10).
inline constexpr double kExampleE1 = 0.105;     // (1.10^2 - 1) / 2
inline constexpr double kExampleE2 = -0.04875;  // (0.95^2 - 1) / 2

}  // namespace sf::test
