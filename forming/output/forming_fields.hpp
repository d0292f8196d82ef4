#pragma once
// Forming results of a ply at a material point (docs/forming.md "Forming results",
// docs/theory/forming_results.md): what a forming engineer reads off a formed laminate.
//
// At a point of ply b with reference fibre a0 (unit), reference ply normal N0 (unit, from
// the bottom to the top face), thickness t0 and deformation gradient F (mid-thickness):
//
//   fibre            a = F a0 / |F a0|            unit, on the deformed ply
//   fibre stretch    lambda_f = |F a0|
//   fibre angle change  the signed angle (degrees, right-handed about N0) from a0 to a
//                    projected onto the reference ply plane: the fibre's rotation seen
//                    in plan view (for a flat part, the in-plane rotation; a rigid
//                    rotation by phi about N0 gives phi)
//   ply shear angle  90 deg - angle(F a0, F b0), b0 = N0 x a0: the ply's own in-plane
//                    shear between its fibres and the material line across them
//                    (positive when they close up)
//   thickness        t = t0 / |F^-T N0| (mm): the distance between the deformed faces
//                    measured along the deformed normal n = F^-T N0 / |F^-T N0|
//   trellis shear angle  against the PARTNER ply (below): theta0 = signed angle (about
//                    N0) from a0 to the partner's a0', theta = signed angle (about n)
//                    from a to the partner's current fibre a' at the same place (the
//                    point projected onto the partner's deformed mid-surface), both
//                    fibres projected onto the plane normal to n;
//                        gamma = sign(theta0) (theta0 - theta)
//                    positive when the angle between the fibre families closes (for a
//                    +-45 pair in bias extension, gamma = 90 deg - the current angle).
//                    NaN without a partner, or where the projection misses it (beyond
//                    its edge or further than the two plies' thicknesses).
//
// The partner of a fibre-reinforced ply is the nearest other fibre-reinforced ply in the
// stack (distance between reference mid-planes along N0) whose reference fibres are not
// parallel (more than 5 degrees apart) and whose plan overlaps; ties go to the ply with
// the smaller index (the one below in a laminate). Plies of isotropic materials
// (diaphragms) have no partner and are nobody's partner.
//
// Wrinkling indicator (per ply, over the n x n column centres of every brick): the signed
// distance d of each point of the deformed mid-surface from a smoothed surface, a
// Gaussian-weighted least-squares quadratic fitted to the neighbours within radius R
// (reference distance; weights exp(-(r / (R/2))^2)) in the local principal plane;
// amplitude = max |d| (mm), rms = sqrt(mean d^2), and the mean wavelength (Rice's
// formula, exact for a sinusoid) lambda = 2 pi sqrt(mean d^2 / mean |grad d|^2), the
// gradient fitted over the nearest samples. R defaults to 3 element sides: waviness
// shorter than about R shows, longer waves (the part's shape) are absorbed by the fit.

#include <limits>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/projection.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

struct PlyPointFields {
  Vec3 X = Vec3::Zero(), x = Vec3::Zero();  // reference and current position, mm
  Mat3 F = Mat3::Identity();
  Vec3 fibre = Vec3::Zero();    // unit current fibre direction
  Vec3 normal = Vec3::UnitZ();  // unit current ply normal
  double fibre_stretch = 1.0;
  double fibre_angle_change_deg = 0.0;
  double ply_shear_deg = 0.0;
  double thickness = 0.0;               // mm
  double trellis_shear_deg = kNoValue;  // NaN without partner
};

struct WrinkleResult {
  std::vector<double> deviation;  // per point, mm (signed along the smoothed surface's normal)
  double radius = 0.0;            // smoothing radius R, mm
  double amplitude = 0.0;         // max |d|, mm
  double rms = 0.0;               // mm
  double wavelength = kNoValue;   // mm; NaN when there is no waviness (rms below 1e-9 of the size)
};

// Wrinkling indicator over points of one ply: reference positions X (neighbourhoods),
// current positions x, the current normals (orientation of d), the smoothing radius R (mm)
// and the sample spacing h (mm, for the gradient fit). See the header.
WrinkleResult wrinkle_indicator(const std::vector<Vec3>& X, const std::vector<Vec3>& x,
                                const std::vector<Vec3>& normals, double radius, double spacing);

class FormingFields {
 public:
  // The model at positions x (n_dofs); the projectors onto every ply's deformed and
  // reference mid-surface are built here.
  FormingFields(const Model& model, const VecX& x);

  // The partner ply of `body` for the trellis shear angle, or -1.
  int partner(int body) const { return partner_[static_cast<std::size_t>(body)]; }
  bool fibre_reinforced(int body) const { return fibrous_[static_cast<std::size_t>(body)]; }

  // The fields at brick `element` of `body`, xi in [0,1]^3 (xi3 = 0.5: mid-thickness).
  PlyPointFields at(int body, Index element, const Vec3& xi) const;

  // The material point of `body`'s reference mid-surface nearest to X: its element and
  // in-plane xi; false when X lies beyond the ply's edge (more than 1e-6 of its size).
  bool locate_reference(int body, const Vec3& X, Index& element, Vec2& xi) const;

  // Largest reference element side of `body`, mm.
  double element_size(int body) const { return element_size_[static_cast<std::size_t>(body)]; }

  // Reference unit normal N0 of `body` (flat plies: the same everywhere).
  Vec3 reference_normal(int body) const { return normal0_[static_cast<std::size_t>(body)]; }

  // Per body: the wrinkling indicator over its n x n column centres per brick (points in
  // element order, then j, then i), radius 0: 3 element sides.
  WrinkleResult wrinkles(int body, int n, double radius = 0.0) const;

 private:
  PlyPointFields local(int body, Index element, const Vec3& xi) const;  // without the trellis angle
  const Model& model_;
  std::vector<MatX> current_;  // per body: unflattened current parameters
  std::vector<mesh::SurfaceProjector> mid_, reference_mid_;
  std::vector<int> partner_;
  std::vector<bool> fibrous_;
  std::vector<double> element_size_;
  std::vector<Vec3> normal0_;
};

}  // namespace sf::forming
