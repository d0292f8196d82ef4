#pragma once
// Compressible neo-Hookean law (an implementation of forming/material/material.hpp) for
// diaphragms and verification cases. Notation: C = F^T F, J = sqrt(det C), Ci = C^-1,
// I1 = tr C; (X (x) Y)_ijkl = X_ij Y_kl and (Ci (.) Ci)_ijkl = (Ci_ik Ci_jl + Ci_il Ci_jk) / 2.
//
// Units: MPa for moduli, stresses and energy density (N/mm^2 = N mm / mm^3), with
// lengths in mm and forces in N. Any consistent set works; the law holds no units.
//
// Voigt conventions (those of forming/material/material.hpp): order (11, 22, 33, 12, 23,
// 13); tangent entries are the plain tensor components CC_IJ = CC_ijkl (no factors of 2),
// so dS = CC dE with dE in voigt_strain form (shear entries 2 dE_12 etc.).
//
// Evaluation at det C <= 0 (an inverted point) is a numerical outcome the element
// must catch before calling; the compressible laws then return W = +infinity and NaN
// stress and tangent rather than throw.

#include <string>

#include "common/core/types.hpp"
#include "forming/material/material.hpp"

namespace sf::forming {

// Compressible neo-Hookean
//   W  = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2
//   S  = mu (I - Ci) + lambda ln J Ci
//   CC = lambda Ci (x) Ci + 2 (mu - lambda ln J) (Ci (.) Ci)
// Small strain: Lame constants mu, lambda; E = mu (3 lambda + 2 mu)/(lambda + mu),
// nu = lambda / (2 (lambda + mu)), bulk modulus kappa = lambda + 2 mu / 3.
// Stress free at C = I.

struct NeoHookeanParams {
  double mu = 0.0;      // shear modulus, MPa (> 0)
  double lambda = 0.0;  // Lame's first parameter, MPa (bulk modulus lambda + 2 mu/3 > 0)

  // From Young's modulus E (MPa, > 0) and Poisson's ratio nu (-1 < nu < 1/2):
  // mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2 nu)). Throws naming "E"/"nu".
  static NeoHookeanParams from_young_poisson(double E, double nu);
  // From shear modulus mu and bulk modulus kappa (MPa): lambda = kappa - 2 mu / 3.
  // Throws naming "mu"/"kappa".
  static NeoHookeanParams from_shear_bulk(double mu, double kappa);

  double bulk_modulus() const { return lambda + 2.0 * mu / 3.0; }
  // Throws sf::InputError naming the bad parameter ("neo-Hookean mu: ...").
  void validate() const;
};

class NeoHookean final : public Material {
 public:
  explicit NeoHookean(const NeoHookeanParams& params);  // validates
  MaterialResponse evaluate(const Mat3& C, bool want_tangent) const override;
  std::string name() const override { return "neo-Hookean"; }
  const NeoHookeanParams& params() const { return params_; }

 private:
  NeoHookeanParams params_;
};

}  // namespace sf::forming
