#pragma once
// Evaluation of fields on a bicubic Hermite surface mesh at any (element, xi).
//
// A SurfaceField binds a mesh to one set of nodal parameters (n_dofs x n_components,
// e.g. the geometry, a fitted deformed position, a displacement) and caches each
// element's 16 xi-parameters. evaluate() computes only what the update flags ask
// for (values, first and/or second xi-derivatives).

#include <Eigen/Core>
#include <vector>

#include "common/basis/hermite.hpp"
#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::fe {

// Field value and xi-derivatives at one point (n_components = 3 for positions).
struct FieldPoint {
  unsigned updated = 0;
  Eigen::VectorXd value;   // u
  Eigen::MatrixXd first;   // n_components x 2: u,1 u,2
  Eigen::MatrixXd second;  // n_components x 3: u,11 u,12 u,22
};

// Fixed-size variant for 3-component fields (positions), used in hot loops.
struct SurfacePoint {
  unsigned updated = 0;
  Vec3 x = Vec3::Zero();
  Mat32 dx = Mat32::Zero();                                               // columns x,1 x,2
  Eigen::Matrix<double, 3, 3> d2x = Eigen::Matrix<double, 3, 3>::Zero();  // columns x,11 x,12 x,22
};

class SurfaceField {
 public:
  // `parameters` is copied into the element cache; it must have mesh.n_dofs() rows.
  SurfaceField(const mesh::SurfaceMesh& mesh, const Eigen::Ref<const MatX>& parameters);

  const mesh::SurfaceMesh& mesh() const { return *mesh_; }
  int n_components() const { return n_components_; }

  // Element xi-parameters, 16 x n_components.
  const MatX& element_parameters(Index e) const { return cache_[e]; }

  FieldPoint evaluate(Index e, const Vec2& xi, unsigned updates) const;
  // Requires n_components() == 3.
  SurfacePoint evaluate3(Index e, const Vec2& xi, unsigned updates) const;
  // With basis values already computed (several fields at one xi).
  SurfacePoint evaluate3(Index e, const basis::BicubicValues& b) const;

 private:
  const mesh::SurfaceMesh* mesh_;
  int n_components_;
  std::vector<MatX> cache_;
};

// Global basis: the coefficients of the global dofs in u(xi) of element e, i.e.
// u(xi) = sum_j coef_j U[dof_j]; `values` selects N, dN/dxi_i (column i of first)
// or a second derivative. Duplicate dofs are merged. Used by assembly.
struct GlobalBasisRow {
  std::vector<Index> dofs;
  std::vector<double> coefs;
};
// `which` = 0 value; 1, 2 first derivative xi1, xi2; 3, 4, 5 second 11, 12, 22.
GlobalBasisRow global_basis_row(const mesh::ElementMap& map, const basis::BicubicValues& b, int which);

// Element matrix form: dense 16 x n_element_dofs map T so that u_e = T U_local,
// with the element's distinct global dofs listed in `dofs`.
struct ElementDofMap {
  std::vector<Index> dofs;  // distinct global dofs of the element
  Eigen::MatrixXd t;        // 16 x dofs.size()
};
ElementDofMap element_dof_map(const mesh::ElementMap& map);

}  // namespace sf::fe
