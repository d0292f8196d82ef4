#pragma once
// Contact laws: normal pressure from the gap, tangential traction from the slip rate.
//
// Normal (per unit REFERENCE area of the contact surface whose points are checked; g the
// gap, mm, negative when the surfaces overlap):
//   penalty                  p = S_n <-g>,                 energy (S_n/2) <-g>^2
//   augmented Lagrangian     p = <lambda - S_n g>,         energy <lambda - S_n g>^2 / (2 S_n)
//     (Uzawa: after each converged solve lambda <- p at every contact point, and the
//      solve is repeated until the largest penetration max(-g) over the points that
//      carry pressure is at most `tolerance`; the penalty alone leaves -g = p / S_n.)
//   <a> = max(a, 0); S_n in N/mm^3 (= MPa/mm), p in MPa, lambda in MPa.
//   The kink of <a> at a = 0 is rounded over a band of width delta in the gap (C1, so
//   Newton converges where many points rest at zero pressure, e.g. the part of a ply
//   lying on a table outside a punch): with t = lambda - S_n g and b = S_n delta,
//     p = 0 (t <= -b/2),   (t + b/2)^2 / (2 b) (|t| < b/2),   t (t >= b/2),
//   energy the integral of p over -g (t^2/2 + b^2/24 above the band). Surfaces that
//   touch exactly (stacked plies, g = 0) have p = S_n delta / 8 and stiffness S_n / 2,
//   so they are held from the first iteration and come apart by delta / 2 at rest.
//   delta = 1e-3 x the ply thickness (forming/contact/surface_contact.cpp).
//   Tail (optional, `tail: S_t` in a case, N/mm^3; `tail_reach: r`, mm): at the band's open
//   end (t = -b/2) the rounded law has p = 0 AND dp = 0, a double root: a point resting
//   there (a ply in a free span, touching nothing but its neighbour) is one Newton cannot
//   place, and converges linearly at best. The tail adds a weak spring about the open end,
//   with x = (t + b/2) / S_n (mm; > 0 inside the open end):
//     p_t = S_t x,  energy S_t x^2 / 2                        (r = 0: linear),
//     p_t = S_t r tanh(x / r),  energy S_t r^2 log cosh(x / r) (r > 0: tension and
//                                                               pressure bounded by S_t r),
//   so the stiffness is S_t > 0 (S_t sech^2(x / r)) at the open end, a simple root.
//   Released (the linear tail, R = tail_release > 0, mm; SurfaceContact sets R to 0.9 x
//   the search distance): with d = -x the parting beyond the open end, the tie S_t d is
//   unchanged up to d = R / 2 and tapers to nothing over [R / 2, R],
//     p_t = -S_t d h(s),  s = (d - R/2) / (R/2),  h = 1 - 3 s^2 + 2 s^3,
//     stiffness S_t (h + d dh/dd) (S_t at R / 2, 0 at R: C1; down to about -1.97 S_t in
//     the taper, a cohesive law's softening), tie at most about 1.08 S_t R / 2,
//   so a point leaving the search distance carries nothing and the residual has no jump
//   there (the plain linear tie grew with the parting and then dropped to 0). The energy
//   is the integral of p, shifted so that it is 0 from d = R on.
//   The bounded tanh tail (r > 0) is not released: its tie, at most S_t r, still drops
//   to nothing where a point leaves the search distance.
//   Beyond the open end p < 0: a weak tie
//   (the tack of the molten resin) that holds a ply to its neighbour where nothing presses
//   them together. Friction (Coulomb) and the augmented multiplier take the rounded
//   penalty's part only (`bearing`), never the tie's.
//
// Tangential (Christie 1997; notes/forming-verification.md section 3.4): with v_T the
// tangential slip rate (slave relative to master, projected on the master's tangent
// plane, mm/s), the traction on the slave surface is  t_T = -c v_T,
//   c = c_f [g <= g_v]  +  mu p / sqrt(|v_T|^2 + eps^2)
// viscous inter-ply slip tau = c_f v (c_f = eta / theta: resin viscosity over the
// inter-layer thickness; of order 2e7 Pa s/m = 0.02 N s/mm^3 in mm-N-s units), acting
// where the gap is below the viscous layer's engage gap g_v (the plies are together;
// c_f tapers smoothly to 0 over one band width delta beyond g_v: c_f h, h = 1 - 3 s^2 + 2 s^3,
// s = (g - g_v) / delta, so the residual has no jump where a gap crosses g_v);
// Coulomb friction tau = mu p regularised below the stick velocity eps (a stiff viscous
// law there: per quasi-static step of length dt a stick stiffness mu p / (eps dt) per
// unit area); both together = the combined (hydrodynamic) law. Rates come from the
// velocities (dynamic runs) or from finite differences over the step (quasi-static runs
// with a process time).
// Coulomb regularised by slip DISTANCE instead (`stick_slip: d`, mm; quasi-static runs):
// an elastic stick with a return map, rate- and step-independent. Each contact point keeps
// its committed elastic slip e (tangential, mm); with du_T the step's tangential relative
// displacement and s = P (e + du), the traction is
//   t_T = -mu p s / max(|s|, d)   (stick while |s| <= d: a spring mu p / d; slip: mu p),
// and at each commit e <- s d / max(|s|, d) (|e| <= d). The velocity form above instead
// sticks below a slip of eps dt a step, which shrinks with every cut-back and restarts
// from zero traction at every step.
//
// Units: mm, N, s, MPa.
#include <string>

namespace sf::forming {

struct NormalLaw {
  double stiffness = 0.0;  // S_n, N/mm^3 (> 0)
  bool augmented = false;  // augmented Lagrangian (Uzawa) on top of the penalty
  double tolerance = 0.0;  // mm, augmented: largest penetration accepted (> 0)
  double tail = 0.0;       // S_t, N/mm^3 (>= 0; 0: no tail, the plain rounded law)
  double tail_reach = 0.0; // r, mm (>= 0; 0: the linear tail)
  double tail_release = 0.0;  // R, mm (>= 0; 0: not released): the linear tie falls to 0 at a parting R
  // Throws sf::InputError naming the field ("contact normal stiffness: ...").
  void validate() const;
};

struct FrictionLaw {
  double viscous = 0.0;         // c_f, N s/mm^3 (>= 0)
  double coulomb = 0.0;         // mu (>= 0)
  double stick_velocity = 0.0;  // eps, mm/s (> 0 when coulomb > 0, unless stick_slip is given)
  double stick_slip = 0.0;      // d, mm: > 0 regularises Coulomb by slip distance instead (below)
  double engage_gap = -1.0;     // g_v, mm; < 0: the default, 0.01 x the ply thickness
  bool active() const { return viscous > 0.0 || coulomb > 0.0; }
  void validate() const;
  // "frictionless", "viscous c_f = ...", "Coulomb mu = ...", "viscous + Coulomb".
  std::string describe() const;
};

// What the normal law gives at a gap.
struct NormalResponse {
  double pressure = 0.0;   // p, MPa (>= 0 without a tail; < 0, a tie, beyond the open end with one)
  double energy = 0.0;     // per unit reference area, N/mm
  double stiffness = 0.0;  // dp/d(-g), N/mm^3: S_n where closed, 0 where open, between in the band (+ the tail's)
  double bearing = 0.0;    // the rounded penalty's part of p (>= 0; = p without a tail), MPa
  double bearing_stiffness = 0.0;  // its d/d(-g), N/mm^3
};

// p, energy and stiffness at gap g (mm) with multiplier lambda (MPa; 0 for the plain
// penalty) and rounding band delta (mm, > 0).
NormalResponse normal_response(const NormalLaw& law, double gap, double lambda, double band);

}  // namespace sf::forming
