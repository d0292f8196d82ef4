#pragma once
// Best-fit plane of a point cloud (the undeformed marks), used by the automatic
// mesh and by the classical method's triangulation; best-fit rigid motion between
// the undeformed and deformed marks, the reference of the deformed fit's smoothing.

#include "common/core/types.hpp"

namespace sf::gsa {

struct PlaneFrame {
  Vec3 centroid, a1, a2, normal;
  double spread1 = 0, spread2 = 0, spread_normal = 0;
};

// PCA plane of the rows of `pts` (n x 3). In-plane axes: for a clearly elongated
// part (a strip) the long axis; otherwise (near-square or round parts, where PCA
// axes are arbitrary) the X axis projected onto the plane. a1 towards +X (else +Y),
// normal = a1 x a2 towards +Z. spread* are standard deviations along the axes.
PlaneFrame best_fit_plane(const Points3& pts);

// x ~= rotation * X + translation.
struct RigidMotion {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
};

// The rigid motion closest to mapping the rows of `from` onto those of `to` in the
// weighted least-squares sense (Kabsch: SVD of the weighted cross-covariance, with
// the sign fixed so the result is a proper rotation). Rows with weight <= 0 are
// ignored (they may hold NaN). Needs three non-collinear rows with weight > 0;
// otherwise the rotation is the identity.
RigidMotion best_rigid_motion(const Points3& from, const Points3& to, const VecX& weight);

}  // namespace sf::gsa
