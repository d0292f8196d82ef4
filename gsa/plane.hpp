#pragma once
// Best-fit plane of a point cloud (the undeformed marks), used by the automatic
// mesh and by the classical method's triangulation.

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

}  // namespace sf::gsa
