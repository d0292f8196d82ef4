#pragma once
// Transversely isotropic ply law (an implementation of forming/material/material.hpp):
// a standard-reinforcing-type energy in I1, I4, I5 about the fibre direction a0,
// incompressible (the element adds p) or compressible (volumetric term below).
//
// Notation (C = F^T F symmetric positive definite, a0 unit fibre direction in the
// reference configuration, A = a0 (x) a0, b = C a0, J = sqrt(det C), Ci = C^-1):
//   I1 = tr C,  I4 = a0.C a0,  I5 = a0.C^2 a0 = |C a0|^2.
//   (I2 = (I1^2 - tr C^2)/2 does not enter these energies.)
// Fourth-order tensors used below, as maps on symmetric second-order tensors:
//   (X (x) Y)_ijkl = X_ij Y_kl,
//   (Ci (.) Ci)_ijkl = (Ci_ik Ci_jl + Ci_il Ci_jk) / 2          (dCi/dC = -(Ci (.) Ci)),
//   (D5)_ijkl = (a_i a_k d_jl + a_i a_l d_jk + a_j a_k d_il + a_j a_l d_ik) / 2
//                                                              (= d2 I5 / dC dC).
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

// Transversely isotropic ply law (standard-reinforcing type, notes section 2.5), with
// c = mu_L - mu_T:
//   W = mu_T/2 (I1 - 3) + c/2 (I5 - 2 I4 + 1) + kappa_f/4 (I4 - 1)^2  [+ W_vol]
//   S = mu_T I + c (a0 (x) b + b (x) a0 - 2 A) + kappa_f (I4 - 1) A     [+ S_vol]
//   CC = 2 kappa_f A (x) A + 2 c D5                                     [+ CC_vol]
// (I5 - 2 I4 + 1 = |(C - I) a0|^2 >= 0.) The fibre terms use I4 itself, not the
// isochoric J^(-2/3) I4, which gives non-physical transverse deformation in
// near-incompressible uniaxial extension (notes section 3.2).
//
// Incompressible (default): no W_vol. The element enforces J = 1 with a pressure
// field, S_total = S - p J Ci; at C = I, S = mu_T I, so the reference state is stress
// free with p = mu_T. This is the form the notes' closed-form cases use.
// Compressible: the neo-Hookean volumetric part with Lame constant lambda, including
// the -mu_T ln J term that makes the reference state stress free:
//   W_vol = -mu_T ln J + lambda/2 (ln J)^2
//   S_vol = (lambda ln J - mu_T) Ci
//   CC_vol = lambda Ci (x) Ci + 2 (mu_T - lambda ln J) (Ci (.) Ci)
// With mu_L = mu_T and kappa_f = 0 the compressible law is exactly NeoHookean.
//
// Small-strain moduli (derived by linearising at C = I, fibre along 1, D = 2 kappa_f
// + 4 (mu_L - mu_T); the normal-stress stiffness block is 2 mu_T I + lambda 1 1^T
// + D e1 e1^T and the shear stiffnesses are G_L = mu_L (planes 12, 13), G_T = mu_T (23)):
//   compressible:   E_L = mu_T (3 lambda + 2 mu_T)/(lambda + mu_T) + D,
//                   E_T = 4 mu_T (a (lambda + mu_T) - lambda^2) / (a (lambda + 2 mu_T) - lambda^2),
//                         a = lambda + 2 mu_T + D,
//                   nu_LT = lambda / (2 (lambda + mu_T)),  nu_TT = E_T / (2 G_T) - 1;
//   incompressible (lambda -> infinity):
//                   E_L = 3 mu_T + D = 3 mu_T + 2 kappa_f + 4 (mu_L - mu_T),
//                   E_T = 4 mu_T E_L / (E_L + mu_T)   (3 mu_T isotropic .. 4 mu_T inextensible),
//                   nu_LT = 1/2, nu_TT = (E_L - mu_T) / (E_L + mu_T).
// The model has four constants (three incompressible), so not every set of
// transversely isotropic engineering constants is reachable; see
// TransverselyIsotropicEngineering.

struct TransverselyIsotropicParams {
  double mu_T = 0.0;     // transverse shear modulus G_T, MPa (> 0)
  double mu_L = 0.0;     // longitudinal shear modulus G_L, MPa (> 0)
  double kappa_f = 0.0;  // fibre-stretch modulus, MPa (>= 0)
  bool incompressible = true;
  double lambda = 0.0;  // compressible only: Lame's first parameter of the matrix, MPa
                        // (matrix bulk modulus lambda + 2 mu_T / 3 > 0)

  // Throws sf::InputError naming the bad parameter ("transversely isotropic mu_T: ...");
  // also rejects constants whose small-strain stiffness is not positive definite
  // (E_L <= 0, named as kappa_f).
  void validate() const;
};

// Engineering constants (MPa) for the ply law; fibre direction "L", across "T".
// Incompressible: give E_f, E_T, G_L (leave G_T = 0: it follows, G_T = mu_T). Inverting
// the formulas above:
//   mu_T = E_f E_T / (4 E_f - E_T)   (needs E_T < 4 E_f),   mu_L = G_L,
//   kappa_f = (E_f + mu_T - 4 G_L) / 2   (needs E_f >= 4 G_L - mu_T).
// Compressible: give E_f, E_T, G_L and G_T (equivalently the transverse Poisson ratio
// nu_TT = E_T / (2 G_T) - 1, which must be < 1). mu_T = G_T, mu_L = G_L and lambda is
// the root of
//   (E_f (1 - nu_TT) - mu_T (1 + nu_TT)) lambda^2 + E_f mu_T (1 - 3 nu_TT) lambda
//       - 2 E_f nu_TT mu_T^2 = 0
// that gives a positive definite stiffness (the other root has lambda ~ -mu_T), then
//   kappa_f = (E_f - mu_T (3 lambda + 2 mu_T)/(lambda + mu_T) - 4 (G_L - G_T)) / 2.
// nu_LT = lambda / (2 (lambda + mu_T)) is then a result, not an input.
// Molten unidirectional GF/PP (BRIEF section 2): E_f about 25000 E_T.
struct TransverselyIsotropicEngineering {
  double E_f = 0.0;  // Young's modulus along the fibres (E_L), MPa
  double E_T = 0.0;  // Young's modulus across the fibres, MPa
  double G_L = 0.0;  // shear modulus in planes containing the fibre, MPa
  double G_T = 0.0;  // shear modulus in the plane of isotropy, MPa: compressible only
  bool incompressible = true;

  // Checks signs and finiteness; throws sf::InputError naming the bad constant.
  void validate() const;
  // Validates, converts as above and validates the result; throws sf::InputError
  // naming the constant to change when the set is not reachable by the model.
  TransverselyIsotropicParams to_params() const;
};

// Small-strain engineering moduli of a parameter set (formulas above), MPa.
struct TransverselyIsotropicModuli {
  double E_L = 0.0, E_T = 0.0, G_L = 0.0, G_T = 0.0;
  double nu_LT = 0.0;  // contraction across / stretch along the fibre, uniaxial fibre stress
  double nu_TT = 0.0;  // in the plane of isotropy
};
TransverselyIsotropicModuli small_strain_moduli(const TransverselyIsotropicParams& params);

class TransverselyIsotropic final : public Material {
 public:
  // Validates params; a0 is normalised (throws sf::InputError naming "fibre direction"
  // when it is zero or not finite). For a ply use fibre_from_layup_angle().
  TransverselyIsotropic(const TransverselyIsotropicParams& params, const Vec3& a0);

  MaterialResponse evaluate(const Mat3& C, bool want_tangent) const override;
  Vec3 fibre_direction() const override { return a0_; }
  std::string name() const override;
  const TransverselyIsotropicParams& params() const { return params_; }

 private:
  TransverselyIsotropicParams params_;
  Vec3 a0_;
  Mat6 fibre_tangent_;  // 2 kappa_f A (x) A + 2 (mu_L - mu_T) d2 I5/dCdC: constant, made once
};

}  // namespace sf::forming
