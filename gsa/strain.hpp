#pragma once
// Surface strain from two fitted surfaces over the same material coordinates xi
// (BRIEF.md §1 "Strains"; docs/theory/strain.md).
//
// At a point: G = [X,1 X,2] (undeformed tangents), g = [x,1 x,2] (deformed),
// M = G^T G, m = g^T g. Principal stretches squared are the generalised
// eigenvalues of m v = lambda^2 M v (lambda1 >= lambda2); v are the principal
// directions in xi, mapped to 3-D as G v / |G v| (undeformed) and g v / |g v|
// (deformed). Exact for curved surfaces: rigid motion and isometric bending
// leave m = M, hence lambda = 1.
//   Green (Lagrangian) E = (lambda^2 - 1)/2, engineering lambda - 1, true ln(lambda).
//   Thickness stretch (incompressible sheet) lambda3 = 1/(lambda1 lambda2);
//   thickness change in percent 100 (lambda3 - 1).

#include <limits>
#include <optional>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa {

struct SurfaceStrain {
  double lambda1 = 0, lambda2 = 0;        // principal stretches, lambda1 >= lambda2
  Vec3 dir1_deformed, dir2_deformed;      // unit major/minor directions, deformed surface
  Vec3 dir1_undeformed, dir2_undeformed;  // the same material directions, undeformed surface
  Vec3 normal_deformed, normal_undeformed;
  double green(int i) const {
    const double l = i == 0 ? lambda1 : lambda2;
    return 0.5 * (l * l - 1.0);
  }
  double engineering(int i) const { return (i == 0 ? lambda1 : lambda2) - 1.0; }
  double true_strain(int i) const;
  double thickness_stretch() const { return 1.0 / (lambda1 * lambda2); }
  double thickness_change_pct() const { return 100.0 * (thickness_stretch() - 1.0); }
};

// Returns nothing when the undeformed or deformed tangents are degenerate
// (e.g. exactly at a collapsed apex): such a point is flagged, never given a strain.
std::optional<SurfaceStrain> surface_strain(const Mat32& G, const Mat32& g);

// Fibre family on the undeformed sheet, given as a unit tangent vector a0 there.
struct FibreState {
  Vec3 direction_deformed;  // unit
  double stretch = 1.0;     // |F a0|
};
std::optional<FibreState> fibre_state(const Mat32& G, const Mat32& g, const Vec3& a0);

// Trellis shear angle (degrees) of two fibre families that started `initial_deg`
// apart and now point along the unit vectors d0, d1: initial minus current angle.
double trellis_shear_deg(double initial_deg, const Vec3& d0, const Vec3& d1);

// Both fibre families at one point (angles in degrees on the undeformed sheet,
// from the X axis, see tangent_at_angle): their undeformed directions, deformed
// states and the trellis shear angle (NaN unless both families are defined).
struct FibrePair {
  std::optional<Vec3> undeformed[2];
  std::optional<FibreState> state[2];
  double shear_angle_deg = std::numeric_limits<double>::quiet_NaN();
};
FibrePair fibre_pair(const Mat32& G, const Mat32& g, double angle0_deg, double angle1_deg);

// Unit tangent at angle `angle_deg` from the reference axis projected on the
// tangent plane of G (anticlockwise about the normal G1 x G2). Falls back to G1's
// direction when the reference axis is (nearly) normal to the surface.
std::optional<Vec3> tangent_at_angle(const Mat32& G, const Vec3& reference_axis, double angle_deg);

}  // namespace sf::gsa
