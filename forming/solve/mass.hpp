#pragma once
// Consistent mass matrix of a Model for the dynamic solver (forming/solve/dynamic_solver.hpp):
//   M_ij = sum over bricks of  int_{V0} rho_b N_k N_l dV0  mapped to global dofs,
// the brick's 32 x 32 scalar mass m_kl = sum_q w_q det G_q rho_b N_k(xi_q) N_l(xi_q)
// (the stiffness' Gauss rule model.rule().brick(), reference volume dV0 = w det G) is
// scattered through PlyMesh::element_map with the scale-factor coefficients:
//   M[3 p + i, 3 p' + i] += coef_k(p) coef_l(p') m_kl  for every coordinate i,
// and M[3 p + i, 3 p' + j] = 0 for i != j (not stored: block diagonal per coordinate).
// Kinetic energy T = 1/2 v^T M v; for a rigid translation u (value parameters = unit
// vector e, derivative parameters 0), u^T M u = total mass.
//
// Units: density t/mm^3, mass t, velocity mm/s, energy N mm (1500 kg/m^3 = 1.5e-9 t/mm^3).
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// Consistent mass matrix (n_dofs x n_dofs, t; symmetric positive semi-definite, block
// diagonal per coordinate). density: one value per body (t/mm^3, finite, >= 0). Throws
// sf::InputError naming "mass matrix density" for a wrong count or value, and for a
// brick whose reference geometry is inverted (det G <= 0 at a Gauss point).
linalg::SparseMatrix mass_matrix(const Model& model, const std::vector<double>& density);

// 1/2 v^T M v (N mm).
double kinetic_energy(const linalg::SparseMatrix& mass, const Eigen::Ref<const VecX>& velocity);

}  // namespace sf::forming
