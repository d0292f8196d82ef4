#include "forming/material/mooney_rivlin.hpp"

#include "common/core/error.hpp"
#include "forming/material/law_support.hpp"

namespace sf::forming {
namespace {

using detail::bad_parameter;
using detail::inverted_response;
using detail::require_finite;
using detail::require_positive;

const char* const kMooneyRivlin = "Mooney-Rivlin";

void require_c01(double c01) {
  require_finite(kMooneyRivlin, "c01", c01);
  if (!(c01 >= 0.0)) bad_parameter(kMooneyRivlin, "c01", "c01 >= 0 (MPa)", c01);
}

}  // namespace

MooneyRivlinParams MooneyRivlinParams::from_bulk(double c10, double c01, double kappa) {
  require_positive(kMooneyRivlin, "c10", c10);
  require_c01(c01);
  require_positive(kMooneyRivlin, "kappa", kappa);
  MooneyRivlinParams p;
  p.c10 = c10;
  p.c01 = c01;
  p.lambda = kappa - 2.0 * p.shear_modulus() / 3.0 - 4.0 * c01;
  return p;
}

MooneyRivlinParams MooneyRivlinParams::from_poisson(double c10, double c01, double nu) {
  require_positive(kMooneyRivlin, "c10", c10);
  require_c01(c01);
  require_finite(kMooneyRivlin, "nu", nu);
  if (!(nu > -1.0 && nu < 0.5)) bad_parameter(kMooneyRivlin, "nu", "-1 < nu < 0.5", nu);
  MooneyRivlinParams p;
  p.c10 = c10;
  p.c01 = c01;
  const double mu = p.shear_modulus();
  p.lambda = 2.0 * mu * nu / (1.0 - 2.0 * nu) - 4.0 * c01;
  return p;
}

double MooneyRivlinParams::young_modulus() const {
  const double mu = shear_modulus();
  return 9.0 * bulk_modulus() * mu / (3.0 * bulk_modulus() + mu);
}

double MooneyRivlinParams::poisson_ratio() const {
  const double mu = shear_modulus();
  return (3.0 * bulk_modulus() - 2.0 * mu) / (2.0 * (3.0 * bulk_modulus() + mu));
}

void MooneyRivlinParams::validate() const {
  require_positive(kMooneyRivlin, "c10", c10);
  require_c01(c01);
  require_finite(kMooneyRivlin, "lambda", lambda);
  if (!(bulk_modulus() > 0.0))
    bad_parameter(kMooneyRivlin, "lambda", "lambda > -4 c01 - 4 (c10 + c01)/3 (positive bulk modulus)", lambda);
}

MooneyRivlin::MooneyRivlin(const MooneyRivlinParams& params) : params_(params) { params_.validate(); }

MaterialResponse MooneyRivlin::evaluate(const Mat3& C, bool want_tangent) const {
  const double c10 = params_.c10;
  const double c01 = params_.c01;
  const double i1 = C.trace();
  const double i2 = 0.5 * (i1 * i1 - (C * C).trace());
  const Mat3 I = Mat3::Identity();

  MaterialResponse r;
  r.energy = c10 * (i1 - 3.0) + c01 * (i2 - 3.0);
  r.stress = 2.0 * c10 * I + 2.0 * c01 * (i1 * I - C);
  // -2 (c10 + 2 c01) ln J + lambda/2 (ln J)^2 and its stress and tangent.
  if (!detail::add_isotropic_volumetric("MooneyRivlin", C, 2.0 * (c10 + 2.0 * c01), params_.lambda, want_tangent, r))
    return inverted_response();
  if (want_tangent && c01 != 0.0) r.tangent += 4.0 * c01 * (detail::outer(I, I) - detail::sym_product(I));
  return r;
}

}  // namespace sf::forming
