#pragma once
// Rigid registration of two parts (docs/usage.md, "Comparing two analyses"):
//
//  * best_fit_rigid: the weighted least-squares rotation and translation between paired
//    points (Kabsch / Horn: SVD of the weighted cross-covariance, det(R) = +1);
//  * robust_rigid_fit: the same, robust to outliers, by iteratively reweighted least
//    squares: scale s = 1.4826 median |r_i| (floored at `min_scale`), Huber weights
//    w_i = min(1, k s / |r_i|) with k = huber_k, and weight 0 (an outlier) where
//    |r_i| > outlier_k s. Exact pairs with gross outliers among them are recovered to
//    round-off;
//  * register_to_surface: iterative closest points onto a fitted bicubic Hermite surface
//    (the nearest point comes from mesh::SurfaceProjector, which searches a CGAL kd-tree
//    of surface samples; the normal there from the surface's tangents), point-to-plane
//    Gauss-Newton steps (the first few point-to-point), Huber-weighted as above; points
//    whose foot point is clamped on a free edge (beyond the other part's edge) do not
//    count; while the starts are probed, only the `trim` fraction of the nearest do. Starts
//    from the identity and from the principal-axes alignments of the points with the
//    surface's samples; the start that ends with the lowest robust RMS wins.
//
// All lengths in the caller's unit (e.g. mm). The transform maps `from` onto `to`
// (the points onto the surface): x_to = R x_from + t.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/projection.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::fe {

struct RigidTransform {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();

  Vec3 apply(const Vec3& x) const { return rotation * x + translation; }
  Points3 apply_all(const Eigen::Ref<const Points3>& points) const;  // row by row
  RigidTransform inverse() const;
  // x -> a(b(x)).
  friend RigidTransform operator*(const RigidTransform& a, const RigidTransform& b);
  double angle_deg() const;  // rotation angle, degrees in [0, 180]
  Vec3 axis() const;         // unit rotation axis (X when the angle is 0)
};

// Weighted least squares: R, t minimising sum w_i |R from_i + t - to_i|^2 (rows of
// n x 3 arrays). Empty weights: all 1. Needs 3 points with weight > 0 not on a line for a
// unique rotation; with fewer the rotation is the nearest proper one the SVD gives.
// Throws std::invalid_argument on a size mismatch.
RigidTransform best_fit_rigid(const Eigen::Ref<const Points3>& from, const Eigen::Ref<const Points3>& to,
                              const std::vector<double>& weights = {});

struct RobustOptions {
  double huber_k = 1.345;    // Huber threshold, robust scales
  double outlier_k = 4.0;    // weight 0 beyond this many robust scales
  double min_scale = 0.0;    // floor of the robust scale (units); 0: 1e-9 of the points' extent
  int max_iterations = 50;   // reweighting passes (>= 1)
  double tolerance = 1e-13;  // relative change of the transform (of the extent) that ends the passes
};

struct RegistrationReport {
  enum class Status { kConverged, kNotConverged, kFailed };
  Status status = Status::kFailed;
  std::string message;  // why, when not converged or failed
  RigidTransform transform;
  int iterations = 0;
  Index n_points = 0;                  // points (pairs) given
  Index n_used = 0;                    // with weight > 0 at the end
  double rms = 0.0;                    // distance RMS over the used points (units)
  double rms_all = 0.0;                // over every point that has a partner (all pairs; ICP: every foot point)
  double scale = 0.0;                  // robust scale at the end (units)
  std::vector<double> distances;       // per point after registration (ICP: to the surface; NaN: no foot point)
  std::vector<bool> used;              // per point: counted in the final fit
  std::string method;                  // "ids" or "surface (ICP)"
  std::string start;                   // ICP: the start that won ("identity", "principal axes ...")
  std::vector<mesh::Projection> feet;  // ICP: per point, its foot point on the surface after registration
  bool ok() const { return status != Status::kFailed; }
  std::string brief() const;  // one line
};
const char* to_string(RegistrationReport::Status status);

// Robust fit of paired points (rows of equal-size arrays; non-finite rows are skipped).
// kFailed with a message when fewer than 3 usable pairs.
RegistrationReport robust_rigid_fit(const Eigen::Ref<const Points3>& from, const Eigen::Ref<const Points3>& to,
                                    const RobustOptions& options = {});

struct IcpOptions {
  RobustOptions robust;
  int max_iterations = 100;    // Gauss-Newton steps per start (>= 1)
  double tolerance = 1e-12;    // step (rotation x extent + translation) below tolerance x extent: converged
  double trim = 0.9;           // while probing a start: fraction of the nearest foot points that count (0.5..1)
  bool principal_axes = true;  // also try the principal-axes alignments as starts
  int probe_iterations = 15;   // steps given to each start before the best is chosen
};

// ICP of `points` (n x 3) onto the surface given by `parameters` (n_dofs x 3) on `mesh`
// (topology built). The principal-axes starts use samples of the surface (element
// centres and corners). Non-finite rows are skipped. kFailed when fewer than 6 points
// find a foot point.
RegistrationReport register_to_surface(const Eigen::Ref<const Points3>& points, const mesh::SurfaceMesh& mesh,
                                       const Eigen::Ref<const MatX>& parameters, const IcpOptions& options = {});

}  // namespace sf::fe
