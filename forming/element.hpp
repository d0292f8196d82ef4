#pragma once
// Total Lagrangian hyperelastic element kernels (principle of virtual work) for the
// ply elements, separate from the material law (forming/material.hpp) and from the
// mesh (the caller maps element xi-parameters to global dofs, forming/ply_mesh.hpp).
//
//   Brick  BicubicHermiteLinear: 32 functions, 3-D; element parameters X_e, x_e are
//          32 x 3 (row k = function k of common/basis/hermite.hpp, k = 4 n + d,
//          columns x, y, z), so X(xi) = sum_k N_k(xi) X_e.row(k).
//   Plane  CubicHermiteLinear (plane strain, unit depth): 8 functions, 2-D;
//          parameters 8 x 2 (x, y); F_33 = 1, the out-of-plane components are zero.
//
// Local element vector ordering: entry D k + i (function k, coordinate i < D), so the
// brick's force is 96 long and its tangent 96 x 96; the plane element's 16 and 16 x 16.
//
// At a Gauss point xi (weight w): G = dX/dxi (D x D), F = dx/dX = (dx/dxi) G^-1,
// C = F^T F, E = (C - I)/2, (S, CC) from the material, dV = w det G,
//   energy  = sum W dV
//   force   f_{ki} = sum P_iJ dN_k/dX_J dV,              P = F S
//   tangent K = sum (B^T CC B + G_geo) dV,
//           B: 6 x (D NF), Voigt rows (11, 22, 33, 2x12, 2x23, 2x13) of dE,
//              dE_IJ = sym(F^T dF)_IJ with dF = dx_k (x) dN_k/dX,
//           G_geo[(k,i),(l,j)] = delta_ij dN_k/dX . S dN_l/dX   (initial stress).
// The tangent is the exact derivative of the force (symmetric).
//
// Quadrature (default, ElementRule): 4 x 4 in-plane x 2 through the thickness for the
// brick, 4 x 2 for the plane element. Why: with an affine reference map the basis
// gradients are of degree <= 3 in each in-plane xi and <= 1 in xi3, so the
// small-strain stiffness integrand B^T D B is of degree <= 6 in-plane and <= 2
// through the thickness: 4-point and 2-point Gauss rules (exact to degree 7 and 3) are
// the smallest that integrate it exactly, i.e. full integration with no spurious zero-
// energy modes for any fibre angle and any stiffness ratio of the anisotropic law.
// (At finite strain the integrand is not polynomial; the rule is then the usual
// full-integration choice; a finer rule can be asked for.)
//
// Inverted points (det G <= 0 or det F <= 0) are a numerical outcome: the result's
// status says so and the caller (Newton) backs off; energy is +inf there.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/quadrature/gauss.hpp"
#include "forming/material.hpp"

namespace sf::forming {

// Gauss points per direction.
struct ElementRule {
  int n_inplane = 4;    // per in-plane direction (xi1, xi2; xi1 for the plane element)
  int n_thickness = 2;  // through the thickness (xi3; xi2 for the plane element)
  // Throws sf::InputError naming the field when a count is outside [1, 32].
  void validate() const;
  quadrature::TensorRule<3> brick() const;
  quadrature::TensorRule<2> plane() const;
};

struct ElementResult {
  enum class Status {
    kOk,
    kInvertedReference,  // det G <= 0 at a Gauss point: bad reference geometry
    kInverted,           // det F <= 0 at a Gauss point: the current state is not admissible
  };
  Status status = Status::kOk;
  double energy = 0.0;  // N mm (= integral of W over the element)
  VecX force;           // D NF, N (internal force, dE/dx)
  MatX tangent;         // D NF x D NF, N/mm (empty unless asked for)
  double min_det_f = 0.0;  // smallest det F over the Gauss points
  bool ok() const { return status == Status::kOk; }
};

using BrickParams = Eigen::Matrix<double, 32, 3>;
using PlaneParams = Eigen::Matrix<double, 8, 2>;

// Brick element: reference and current xi-parameters (32 x 3, mm).
ElementResult brick_element(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                            const quadrature::TensorRule<3>& rule, bool want_tangent);
// Plane-strain element (per unit depth: energy N mm/mm, force N/mm).
ElementResult plane_element(const PlaneParams& X_e, const PlaneParams& x_e, const Material& material,
                            const quadrature::TensorRule<2>& rule, bool want_tangent);

// Deformation gradient at every point of the rule (order of rule.points); the plane
// element's F is embedded in 3 x 3 with F_33 = 1.
std::vector<Mat3> brick_deformation_gradients(const BrickParams& X_e, const BrickParams& x_e,
                                              const quadrature::TensorRule<3>& rule);
std::vector<Mat3> plane_deformation_gradients(const PlaneParams& X_e, const PlaneParams& x_e,
                                              const quadrature::TensorRule<2>& rule);

std::string to_string(ElementResult::Status status);

}  // namespace sf::forming
