#pragma once
// Hyperelastic materials for the forming solver, separate from the element loop
// (STYLE.md, MFEM-style): a material maps the right Cauchy-Green tensor C (3x3,
// symmetric) at a quadrature point to the strain energy W (per unit reference
// volume), the second Piola-Kirchhoff stress S = 2 dW/dC and the material
// tangent CC = 4 d2W/dCdC (so dS = CC : dE with dE = dC/2).
//
// Voigt order for symmetric 3x3 tensors everywhere in forming/: (11, 22, 33, 12, 23, 13);
// tangents are 6x6 holding the plain tensor components CC_IJ = CC_ijkl (I ~ ij,
// J ~ kl; no factors of 2), so dS_I = sum_J CC_IJ dE_J holds with dE in
// voigt_strain() form (shear entries doubled: 2 dE_12, 2 dE_23, 2 dE_13) and S in
// voigt_stress() form (plain components).
//
// Constraints (exact incompressibility J = 1, fibre inextensibility I4 = 1) are
// NOT part of the material: the element adds -p J C^-1 and T a0 (x) a0 with
// separately interpolated p and T (mixed formulation). A material reports the
// fibre direction a0 (unit, reference configuration) it was built with.
//
// Units: stresses and moduli in MPa with lengths in mm and forces in N.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "common/core/types.hpp"

namespace sf::forming {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

struct MaterialResponse {
  double energy = 0.0;          // W, MPa (energy per unit reference volume)
  Mat3 stress = Mat3::Zero();   // S, second Piola-Kirchhoff, MPa
  Mat6 tangent = Mat6::Zero();  // CC = 4 d2W/dCdC in Voigt form, MPa
};

class Material {
 public:
  virtual ~Material() = default;
  // Evaluates W, S and (when want_tangent) CC at right Cauchy-Green tensor C.
  virtual MaterialResponse evaluate(const Mat3& C, bool want_tangent) const = 0;
  // Fibre direction in the reference configuration (unit); zero vector for isotropic materials.
  virtual Vec3 fibre_direction() const { return Vec3::Zero(); }
  virtual std::string name() const = 0;
};

// Symmetric 3x3 <-> Voigt (11, 22, 33, 12, 23, 13).
Vec6 voigt_stress(const Mat3& s);  // plain components
Vec6 voigt_strain(const Mat3& e);  // shear components doubled
Mat3 from_voigt_stress(const Vec6& v);

// Fibre direction of a ply from its layup angle theta (degrees, in the ply plane x-y,
// measured from x towards y): a0 = (cos theta, sin theta, 0). Throws sf::InputError
// naming "layup angle" when theta is not finite.
Vec3 fibre_from_layup_angle(double theta_deg);

// Cauchy stress sigma = F S F^T / det F from the deformation gradient F and a second
// Piola-Kirchhoff stress S (MPa). Constraint stresses are added by the caller:
// -p J C^-1 in S gives -p I in sigma; T a0 (x) a0 in S gives (T/J) a (x) a, a = F a0.
Mat3 cauchy_stress(const Mat3& F, const Mat3& S);

}  // namespace sf::forming
