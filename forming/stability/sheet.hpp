#pragma once
// Buckling stability of a viscous sheet in homogeneous in-plane flow (docs/theory/stability.md).
//
// The sheet: an incompressible Newtonian fluid of viscosity mu, thickness h, free upper and
// lower surfaces, optionally reinforced by two families of inextensible fibres lying in the
// plane of the sheet (directions a and b, tensions T_a and T_b: reaction stresses, force per
// unit area of the sheet's cross-section). Coordinates: x1, x2 in the mid-plane, x3 normal.
//
// Background (homogeneous) flow: velocity v = D x with the in-plane rate of deformation
// D (2x2, symmetric) and D33 = -(D11 + D22) (incompressibility); no spin. With
// fibres, a.D.a = b.D.b = 0 (inextensibility): a trellis flow. The stress is
//   sigma = -p I + T_a a(x)a + T_b b(x)b + 2 mu D,  p = 2 mu D33 (free surfaces),
// so the in-plane stress is sigma_par = 2 mu (D + tr(D) I) + T_a a(x)a + T_b b(x)b.
//
// Perturbation: out-of-plane buckles exp(i K n.x), n = (cos theta, sin theta) the wave
// direction (crests run along t = (-sin theta, cos theta)), K > 0 the wave number,
// wavelength 2 pi / K. The convected growth rate G is d(ln amplitude)/dt following the
// background flow (the wave vector is carried by the flow, the amplitude is the vertical
// displacement of the sheet). G_rel = G - D33 is the growth relative to the thickness.
//
// Units: any consistent set; the samples use mm, s and MPa (viscosity MPa s, rates 1/s,
// tensions MPa, growth rates 1/s).

#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::forming::stability {

// One family of fibres in the plane of the sheet.
struct Fibre {
  Vec2 direction = Vec2::UnitX();  // unit, in the x1-x2 plane
  double tension = 0.0;            // T, MPa (positive: tension)
};

// Background state of the sheet; plain data, checked by validate().
struct SheetState {
  Mat2 rate = Mat2::Zero();   // in-plane rate of deformation D (symmetric), 1/s
  double viscosity = 1.0;     // mu > 0, MPa s
  double thickness = 1.0;     // h > 0, mm
  std::vector<Fibre> fibres;  // none (Newtonian sheet) or two non-parallel families

  // D33 = -(D11 + D22), 1/s.
  double rate33() const { return -rate.trace(); }
  // In-plane background stress sigma_par (symmetric 2x2), MPa.
  Mat2 in_plane_stress() const;
  // Fibre stress tensor M = sum T_f f(x)f (symmetric 2x2), MPa.
  Mat2 fibre_stress() const;
  // Fibre tension resolved in direction n: T_n = n.M.n = sum T_f (n.f)^2, MPa.
  double resolved_tension(const Vec2& n) const;

  // Programmer checks (SF_ASSERT-level conditions, thrown as std::invalid_argument so tests
  // can see them): mu > 0, h > 0, symmetric D, unit fibre directions, 0 or 2 families,
  // fibres not parallel, a.D.a = b.D.b = 0 to `relative_tolerance` of |D|.
  void validate(double relative_tolerance = 1e-9) const;
};

// Unit wave direction n(theta) and crest direction t(theta).
Vec2 wave_direction(double theta);
Vec2 crest_direction(double theta);

// ---------------------------------------------------------------------------------------
// Closed forms (docs/theory/stability.md, sections 4 and 5)

// Fibre-reinforced sheet (two families): the perturbation is a uniform vertical shift of
// every fibre layer (u = W e3, no in-plane motion) and
//   G = D33 - T_n / mu,   T_n = T_a (n.a)^2 + T_b (n.b)^2,
// for every wave number (independent of kappa). Valid when n is normal to neither family
// (n.a != 0 and n.b != 0); at those two directions the ideal model admits further modes and
// the value returned is the limit from neighbouring directions (see normal_to_fibre()).
double fibre_sheet_growth_rate(const SheetState& sheet, double theta);
// True when |n.f| <= tolerance for a family f (the exceptional directions above).
bool normal_to_fibre(const SheetState& sheet, double theta, double tolerance = 1e-9);

// Newtonian sheet without fibres (exact Stokes solution of the free layer), q = K h:
//   sinuous (bending) mode:     G = D33 - (S_n / mu) q / (2 (sinh q - q)),
//   varicose (thickness) mode:  G = D33 + (S_n / mu) q / (2 (sinh q + q)),
// S_n = n.sigma_par.n the in-plane stress resolved in the wave direction (MPa).
// Long waves: G_sinuous -> D33 - 3 S_n / (mu q^2) (thin viscous sheet bending).
struct NewtonianGrowthRates {
  double sinuous = 0.0;   // 1/s
  double varicose = 0.0;  // 1/s
};
NewtonianGrowthRates newtonian_sheet_growth_rates(const Mat2& rate, double viscosity, double thickness, double theta,
                                                  double wave_number);
// sinh(q) - q and sinh(q) + q without cancellation for small q (q >= 0).
double sinh_minus_identity(double q);

// ---------------------------------------------------------------------------------------
// Non-dimensional groups (docs/theory/stability.md, section 6)
//
//   kappa = (K h)^2                      wave number squared
//   tau   = T_n / (mu |gamma_dot|)       fibre tension factor (resolved in n)
//   Gamma = G / |gamma_dot|              growth factor
// gamma_dot = -d(chi)/dt is the trellis shear rate (chi the angle between the families);
// D33 = gamma_dot cot(chi), so Gamma = s |cot chi| - tau with s = +1 for a thickening
// (D33 > 0) and -1 for a thinning flow. Gamma does not depend on kappa (section 4), so the
// function takes none.
enum class FlowKind { kThickening, kThinning };
double growth_factor(double tau, double fibre_angle_chi, FlowKind kind);

}  // namespace sf::forming::stability
