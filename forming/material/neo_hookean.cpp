#include "forming/material/neo_hookean.hpp"

#include "common/core/error.hpp"
#include "forming/material/law_support.hpp"

namespace sf::forming {
namespace {

using detail::bad_parameter;
using detail::inverted_response;
using detail::require_finite;
using detail::require_positive;

const char* const kNeoHookean = "neo-Hookean";

}  // namespace

NeoHookeanParams NeoHookeanParams::from_young_poisson(double E, double nu) {
  require_positive(kNeoHookean, "E", E);
  require_finite(kNeoHookean, "nu", nu);
  if (!(nu > -1.0 && nu < 0.5)) bad_parameter(kNeoHookean, "nu", "-1 < nu < 0.5", nu);
  NeoHookeanParams p;
  p.mu = E / (2.0 * (1.0 + nu));
  p.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  return p;
}

NeoHookeanParams NeoHookeanParams::from_shear_bulk(double mu, double kappa) {
  require_positive(kNeoHookean, "mu", mu);
  require_positive(kNeoHookean, "kappa", kappa);
  NeoHookeanParams p;
  p.mu = mu;
  p.lambda = kappa - 2.0 * mu / 3.0;
  return p;
}

void NeoHookeanParams::validate() const {
  require_positive(kNeoHookean, "mu", mu);
  require_finite(kNeoHookean, "lambda", lambda);
  if (!(bulk_modulus() > 0.0)) bad_parameter(kNeoHookean, "lambda", "lambda > -2 mu/3 (positive bulk modulus)", lambda);
}

NeoHookean::NeoHookean(const NeoHookeanParams& params) : params_(params) { params_.validate(); }

MaterialResponse NeoHookean::evaluate(const Mat3& C, bool want_tangent) const {
  const double mu = params_.mu;
  MaterialResponse r;
  r.energy = 0.5 * mu * (C.trace() - 3.0);
  r.stress = mu * Mat3::Identity();
  if (!detail::add_isotropic_volumetric("NeoHookean", C, mu, params_.lambda, want_tangent, r))
    return inverted_response();
  return r;
}

}  // namespace sf::forming
