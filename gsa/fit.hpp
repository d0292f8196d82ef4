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
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/fe/surface_field.hpp"
#include "common/linalg/sparse.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::gsa {

struct Penalty {
  double alpha = 0.0;
  double beta = 0.0;
  double gamma = 0.0;
  double delta = 0.0;  // fourth order (edge jumps of u,nn and u,nnn), units^6
  // Third order on the elements at the mesh's boundary: the mean of |u,sss|^2 (1, 3, 3, 1
  // weights) over each, units^6 like delta. It takes the cubic freedom out of the
  // boundary elements, where the jumps alone leave a one-sided bicubic whose slope is
  // noisy (the edge variance of a polynomial fit); automatic smoothing sets it by
  // cross-validation (gsa/smoothing.hpp).
  double boundary = 0.0;
};

// Location of a data point on the mesh.
struct MeshLocation {
  Index element = -1;
  Vec2 xi = Vec2::Zero();
};

// Penalty matrices of each order (n_dofs x n_dofs, symmetric PSD), assembled once
// per mesh and weighted later (automatic smoothing tries several weights). They
// are stored as values on one sparsity pattern that also holds every element
// block and the diagonal, so K = normal matrix + sum of weighted orders is
// formed by adding value arrays.
struct PenaltyMatrices {
  linalg::SparseMatrix pattern;         // union pattern (its values are not used)
  std::array<VecX, 5> order;            // first .. fourth order, boundary third order: values on the pattern
  std::vector<int> diagonal;            // position of (i, i) in the pattern's values
  std::vector<fe::ElementDofMap> maps;  // element dof maps
  // Per element: position in the pattern's values of (dofs[i], dofs[j]), at i + j * dofs.size().
  std::vector<std::vector<int>> element_positions;
};
PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh);
// The same with a multiplier per element (n_elements, > 0) on its interior terms; an
// edge's terms take the smaller multiplier of its two elements (locally relaxed
// smoothing where the field varies sharply, gsa/local_smoothing.hpp).
PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh, const std::vector<double>& element_multiplier);

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
// penalties in turn. Built once: the collocation matrix Phi (row d: the global basis at (e_d, xi_d)),
// the normal matrix Phi^T W Phi (summed element by element), and one sparsity
// pattern holding it and every penalty order, so a new set of weights only
// rescales stored values; the sparse factorisation's symbolic analysis is reused,
// and an unchanged matrix is not factorised again.
class FitSystem {
 public:
  // `weights` (n_points, >= 0; 0 excludes a point) may be empty (all 1).
  // `penalties` must outlive the system.
  FitSystem(const mesh::SurfaceMesh& mesh, const PenaltyMatrices& penalties, const std::vector<MeshLocation>& locations,
            const VecX& weights);
  ~FitSystem();
  FitSystem(const FitSystem&) = delete;
  FitSystem& operator=(const FitSystem&) = delete;
  // The data z (n_points x n_components; rows with weight 0 may be NaN). Kept
  // until replaced: every solve() fits these.
  void set_values(const Eigen::Ref<const MatX>& values);
  // Fits the values with `penalty`; `reference` is U_ref (n_dofs x n_components).
  // Dofs no element uses, and dofs nothing determines, are pinned to the
  // reference. With trace_probes > 0 the effective degrees of freedom (trace of
  // the hat matrix Phi K^-1 Phi^T W, per component) are estimated with that many
  // Rademacher probes (Hutchinson; fixed seed, drawn once per system) from the
  // same factorisation.
  // With passes > 1 the fit is iterated (iterated Tikhonov): each pass penalises the
  // deviation from the previous pass's solution instead of from the reference, so
  // the bias (I - A)(U - U_ref) of one pass becomes (I - A)^passes (U - U_ref); the
  // degrees of freedom are those of the iterated smoother.
  // `slot` (0 or 1) is the workspace (factorisation) used: solves in different slots, with
  // trace_probes = 0, may run at once on two threads (the noise ladders fit two pilots
  // at a time); each slot keeps its own last factorisation.
  FitResult solve(const Penalty& penalty, const Eigen::Ref<const MatX>& reference, int trace_probes = 0,
                  int passes = 1, int slot = 0);
  // values - H values: the residuals of fitting other data at the same points with the
  // same weights (e.g. noise probes, n_points x k) with `penalty` and a zero reference.
  // The system's own data stay as they are; no copy of `values` is kept and no fitted
  // values or residual norms are stored (with 1e5 points and 42 probe columns each such
  // temporary is 34 MB). Nothing when the system is singular.
  std::optional<MatX> smoothing_residual(const Eigen::Ref<const MatX>& values, const Penalty& penalty, int passes = 1);
  // Phi^T W values (n_dofs x k), what the fit of `values` starts from. Data smoothed with
  // several penalties (the noise ladders' probe fields, at every pilot) need it once.
  MatX weighted_values(const Eigen::Ref<const MatX>& values) const;
  // The same with `weighted` = weighted_values(values) given, in workspace `slot` (see
  // solve()), at the points `rows` only when given (rows->size() x k, in its order; each
  // the same bits as in the whole).
  std::optional<MatX> smoothing_residual(const Eigen::Ref<const MatX>& values, const MatX& weighted,
                                         const Penalty& penalty, int passes = 1, int slot = 0,
                                         const std::vector<Index>* rows = nullptr);
  // Probes of the trace estimate given by the caller (n_points x count) instead of
  // Rademacher ones: with probes drawn from the noise N(0, Sigma) the estimate is
  // tr(H Sigma) (gsa/noise_model.hpp). Later solves with trace_probes = count use them.
  void set_probes(const MatX& probes);
  // Two penalties at once, on two threads where the machine has two cores (each
  // with its own factorisation; automatic smoothing compares pairs).
  std::array<FitResult, 2> solve_pair(const std::array<Penalty, 2>& penalties, const Eigen::Ref<const MatX>& reference,
                                      int trace_probes = 0, int passes = 1);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sf::gsa
