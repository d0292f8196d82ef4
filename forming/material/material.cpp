#include "forming/material/material.hpp"

#include <Eigen/LU>
#include <cmath>

#include "forming/material/law_support.hpp"

namespace sf::forming {

Vec6 voigt_stress(const Mat3& s) {
  Vec6 v;
  v << s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(1, 2), s(0, 2);
  return v;
}

Vec6 voigt_strain(const Mat3& e) {
  Vec6 v;
  v << e(0, 0), e(1, 1), e(2, 2), 2.0 * e(0, 1), 2.0 * e(1, 2), 2.0 * e(0, 2);
  return v;
}

Mat3 from_voigt_stress(const Vec6& v) {
  Mat3 s;
  s << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
  return s;
}

Vec3 fibre_from_layup_angle(double theta_deg) {
  detail::require_finite("ply", "layup angle", theta_deg);
  const double t = theta_deg * kPi / 180.0;
  return Vec3(std::cos(t), std::sin(t), 0.0);
}

Mat3 cauchy_stress(const Mat3& F, const Mat3& S) { return F * S * F.transpose() / F.determinant(); }

}  // namespace sf::forming
