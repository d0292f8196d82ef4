#pragma once
// Penalised least-squares fit of a field on a bicubic Hermite surface mesh
// (BRIEF.md §1, "Fitting by penalised least squares").
//
// For data points d at fixed locations (element e_d, xi_d) with values z_d
// (n_points x n_components) the fit minimises, per component,
//
//   sum_d w_d (u(xi_d) - z_d)^2  +  (U - U_ref)^T P (U - U_ref)
//
// where P is the assembled smoothing penalty and U_ref a reference field (the
// smoothing acts on the DEVIATION from U_ref: the displacement when U_ref is the
// fitted undeformed surface, so the smoothing does not shrink the part).
//
// Penalty, in PHYSICAL units (derivatives by arc length, approximated on each
// element by xi-derivatives divided by the element's sizes h1, h2 = its mean
// scale factors), so the weights mean the same after mesh refinement:
//
//   alpha * int |u,s|^2            (first derivatives; stretches the surface)
// + beta  * int |u,s1s1|^2 + 2|u,s1s2|^2 + |u,s2s2|^2          (curvature, the brief's)
// + gamma * [ int |u,sss|^2 (1, 3, 3, 1 weights)
//             + sum over interior edges int_edge [u,nn]^2 ds / h_n ]   (third order)
//
// + delta * sum over interior edges int_edge ( [u,nn]^2 / h_n^3 + [u,nnn]^2 / h_n ) ds
//                                                             (fourth order, "jumps")
// The fourth-order (jump) term has no interior integral: it only asks the fitted
// displacement to be C3 across element edges, so its null space is the bicubic
// polynomials and smooth non-polynomial shapes (a bent sheet's displacement) are
// biased far less than by the third-order interior integral.
// The third-order term leaves quadratic fields unpenalised, so it does not force
// zero curvature at free edges (the boundary bias of the beta term); the edge
// term penalises the jump of the normal second derivative across element edges,
// which bicubic C1 elements allow. 4x4 Gauss points per element (exact in xi).
// Units: with lengths in mm, alpha is dimensionless * mm^0, beta mm^2,
// gamma mm^4 per unit data weight (all relative to the data term per point).

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/sparse.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::gsa {

struct Penalty {
  double alpha = 0.0;
  double beta = 0.0;
  double gamma = 0.0;
  double delta = 0.0;  // fourth order (edge jumps of u,nn and u,nnn), units^6
};

// Location of a data point on the mesh.
struct MeshLocation {
  Index element = -1;
  Vec2 xi = Vec2::Zero();
};

// Penalty matrices of each order (n_dofs x n_dofs, symmetric PSD), assembled once
// and combined with weights later (automatic smoothing tries several).
struct PenaltyMatrices {
  linalg::SparseMatrix first, second, third, fourth;
  linalg::SparseMatrix combined(const Penalty& p) const;
};
PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh);

// Sparse collocation matrix Phi (n_points x n_dofs): row d holds the global basis
// at (e_d, xi_d), so u(xi_d) = Phi U.
linalg::SparseMatrix collocation_matrix(const mesh::SurfaceMesh& mesh,
                                        const std::vector<MeshLocation>& locations);

struct FitResult {
  MatX parameters;   // n_dofs x n_components
  MatX fitted;       // n_points x n_components: u(xi_d)
  VecX residual;     // n_points: |u(xi_d) - z_d|
  double rms = 0.0;  // RMS of residual over points with weight > 0
  double max = 0.0;
  double edf = std::numeric_limits<double>::quiet_NaN();  // trace of the hat matrix (estimated)
  bool ok = false;
  std::string message;
};

// A least-squares system (point locations and weights fixed) solved for several
// penalties in turn: the normal matrix Phi^T W Phi (Phi = collocation_matrix(mesh,
// locations)) is summed once, element by element, and the sparse factorisation's
// symbolic analysis is reused while the pattern stays the same.
class FitSystem {
 public:
  // `weights` (n_points, >= 0; 0 excludes a point) may be empty (all 1).
  FitSystem(const mesh::SurfaceMesh& mesh, const std::vector<MeshLocation>& locations, const VecX& weights);
  ~FitSystem();
  FitSystem(const FitSystem&) = delete;
  FitSystem& operator=(const FitSystem&) = delete;
  // Solves the fit of `values` (n_points x n_components) with `penalty`; `reference`
  // is U_ref (n_dofs x n_components). Dofs no element uses are pinned to the
  // reference. With trace_probes > 0 the effective degrees of freedom (trace of the
  // hat matrix Phi K^-1 Phi^T W, per component) are estimated with that many
  // Rademacher probes (Hutchinson; fixed seed, drawn once per system) from the same
  // factorisation.
  FitResult solve(const Eigen::Ref<const MatX>& values, const linalg::SparseMatrix& penalty,
                  const Eigen::Ref<const MatX>& reference, int trace_probes = 0);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sf::gsa
