#pragma once
// Compressible Mooney-Rivlin law (an implementation of forming/material/material.hpp) for
// rubber diaphragms, beside NeoHookean (neo_hookean.hpp; same notation and Voigt
// conventions). I2 = (I1^2 - tr C^2) / 2 is the second invariant of C.
//
//   W  = c10 (I1 - 3) + c01 (I2 - 3) - 2 (c10 + 2 c01) ln J + lambda/2 (ln J)^2
//   S  = 2 c10 I + 2 c01 (I1 I - C) + (lambda ln J - 2 (c10 + 2 c01)) Ci
//   CC = 4 c01 (I (x) I - II) + lambda Ci (x) Ci + 2 (2 c10 + 4 c01 - lambda ln J) (Ci (.) Ci)
// with II the symmetric fourth-order identity. Stress free at C = I. Small strain:
// shear modulus mu = 2 (c10 + c01), Lame lambda_0 = lambda + 4 c01, bulk modulus
// kappa = lambda + 4 c01 + 2 mu / 3. With c01 = 0 it is exactly NeoHookean with
// mu = 2 c10.
//
// Units: MPa for c10, c01, lambda, stresses and energy density (mm, N).
// At det C <= 0 the law returns W = +infinity and NaN stress/tangent (as NeoHookean).

#include <string>

#include "common/core/types.hpp"
#include "forming/material/material.hpp"

namespace sf::forming {

struct MooneyRivlinParams {
  double c10 = 0.0;     // MPa (> 0)
  double c01 = 0.0;     // MPa (>= 0; c10, c01 >= 0 keeps the law polyconvex)
  double lambda = 0.0;  // MPa, volumetric constant (small-strain bulk modulus > 0)

  // From c10, c01 and the small-strain bulk modulus kappa (MPa):
  // lambda = kappa - 2 mu / 3 - 4 c01 with mu = 2 (c10 + c01). Throws naming the parameter.
  static MooneyRivlinParams from_bulk(double c10, double c01, double kappa);
  // From c10, c01 and the small-strain Poisson ratio nu (-1 < nu < 1/2).
  static MooneyRivlinParams from_poisson(double c10, double c01, double nu);

  double shear_modulus() const { return 2.0 * (c10 + c01); }
  double bulk_modulus() const { return lambda + 4.0 * c01 + 2.0 * shear_modulus() / 3.0; }
  double young_modulus() const;
  double poisson_ratio() const;
  // Throws sf::InputError naming the bad parameter ("Mooney-Rivlin c10: ...").
  void validate() const;
};

class MooneyRivlin final : public Material {
 public:
  explicit MooneyRivlin(const MooneyRivlinParams& params);  // validates
  MaterialResponse evaluate(const Mat3& C, bool want_tangent) const override;
  std::string name() const override { return "Mooney-Rivlin"; }
  const MooneyRivlinParams& params() const { return params_; }

 private:
  MooneyRivlinParams params_;
};

}  // namespace sf::forming
