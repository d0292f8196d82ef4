#pragma once
// Closest point of one contact-surface face to a point p (Newton's method, as in
// common/mesh/projection.hpp): minimise f(zeta) = |p - x(zeta)|^2 / 2 over zeta in
// [0,1]^2 for the face patch x(zeta) = sum_b M_b(zeta) x_b (forming/contact/
// contact_surface.hpp), gradient -x,a . r, Hessian H = x,a . x,b - r . x,ab (r = p - x);
// Gauss-Newton where H is not positive definite; steps limited to 0.5 in zeta and
// halved while f increases; a component on a bound with the gradient pushing outward
// is held there (the point slides along the edge). Started from the nearest of a
// 3 x 3 grid of samples. Converged when the zeta step is below 1e-13: the contact
// tangent differentiates the closest-point condition, so zeta must be exact to
// round-off.
//
// The result says whether the foot point is a true closest point of the face
// (interior, or on an edge with zero gradient) or was stopped at an edge by the bound
// (`exit_edge`: s = 0, s = 1, t = 0, t = 1 as 0..3, the numbering of SurfaceFace::
// free_edge): beyond a free edge of the surface the point has no partner.
#include "common/core/types.hpp"
#include "forming/contact/contact_surface.hpp"

namespace sf::forming {

struct FaceFoot {
  Vec2 zeta = Vec2::Zero();
  Vec3 x = Vec3::Zero();                      // x(zeta)
  Vec3 x1 = Vec3::Zero(), x2 = Vec3::Zero();  // x,s  x,t
  Vec3 x11 = Vec3::Zero(), x12 = Vec3::Zero(), x22 = Vec3::Zero();
  double distance = 0.0;  // |p - x|
  int exit_edge = -1;     // the bound that stopped it with an outward gradient, or -1
  bool converged = false;
};

// positions: the face's active-function positions (n_active x 3).
FaceFoot project_on_face(const FaceBasis& basis, const Eigen::Ref<const MatX>& positions, const Vec3& p);

}  // namespace sf::forming
