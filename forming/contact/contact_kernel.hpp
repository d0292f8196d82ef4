#pragma once
// The contribution of one contact point: a point x_s of the slave surface (fixed face
// coordinates), its gap to the opposing surface and the tractions of the contact laws
// (forming/contact/contact_law.hpp), as energy, force, stiffness and damping over the
// point's LOCAL dofs: entry 3 a + i for local function a and coordinate i, the slave
// face's active functions first (a < n_slave), then the master face's (none against a
// rigid tool). With phi_a = N_a(s, t) on the slave and phi_b = -M_b(zeta) on the master,
//   r = x_s - x_m(zeta) = J u,   J = phi^T (x) I_3,   v_rel = J v (slave minus master).
//
// Gap and its derivatives.
//   Rigid tool: g, n = the shape's gap and normal at x_s, dg/dx_s and dn/dx_s
//     (forming/contact/tool_shape.hpp); dg/du = phi (x) dg/dx, dn/du = dn/dx J.
//   Body surface (master face, foot point zeta = closest point, r = g n):
//     T = [x_m,1 x_m,2], M = T^T T, kappa_ab = n . x_m,ab, H = M - g kappa (the
//     projection's Hessian), rho_a = (M_b,1, M_b,2) on master functions (0 on slave);
//     dg/du = phi (x) n and the exact second derivative (implicit differentiation of
//     the closest-point condition; it holds at g = 0 too):
//       d2g = -[ J^T T C T^T J + Rh^T H^-1 T^T J + J^T T H^-1 Rh + g Rh^T H^-1 Rh ],
//       C = M^-1 kappa H^-1 (symmetric), Rh_(a,i) = rho_a n_i,
//     per 3 x 3 block (a, c):
//       d2g_ac = -[ phi_a phi_c T C T^T + phi_c n q_a^T + phi_a q_c n^T
//                   + g (rho_a . H^-1 rho_c) n n^T ],   q_a = T H^-1 rho_a;
//     the moving foot point: dzeta/du = H^-1 (T^T J + g Rh), and the normal
//     dn/du = -T M^-1 (Rh + kappa dzeta/du).
// Normal contact (w = the point's quadrature weight x reference area, mm^2):
//   energy  w psi,  force  -w p J^T n,
//   stiffness  tool: w phi_a phi_c (S n (dg/dx)^T - p dn/dx);
//              body: w (S dg dg^T - p d2g),   S = the law's stiffness where closed.
//   (Force along n: for a meshed tool n is not dg/dx, and the tangent is unsymmetric.)
// Friction: v_T = P v_rel (P = I - n n^T), c = c_v + mu p / s, s = sqrt(|v_T|^2 + eps^2),
//   c_v = c_f h(g) the viscous coefficient where the layer is engaged,
//   force  w c J^T v_T,
//   stiffness  w [ (J^T v_T) dc/du + c (dJ^T/du) v_T + c J^T dv_T/du ],
//     dv_T/du = -(n . v_rel) dn/du - n (v_rel^T dn/du) + P dv_rel/du,
//     dv_rel/du = J / dt (quasi-static rates; 0 in dynamics) - sum_a m_a dzeta_a/du,
//       m_a = d v_m / d zeta_a (the master's velocity gradient along its face),
//     (dJ^T/du v_T)_((a,i), col) = -sum_a rho_a,a v_T,i dzeta_a/du,
//     dc/du = c_v' dg/du + (mu / s) dp/du - (mu p / s^3) v_T^T dv_T/du,  dp/du = -S dg/du,
//       c_v' = d(c_f h)/dg, the engagement taper of the viscous layer (PointLaw);
//   damping (dynamic runs)  w [ (J^T v_T) dc/dv + c J^T P J ],  dc/dv = -(mu p/s^3) v_T^T J.
//   Slip-distance Coulomb (quasi-static): Coulomb acts on v_T,c = P (v_rel + e / dt), e the
//   committed elastic slip, with s = max(|v_T,c|, eps), eps = the slip distance / dt: the
//   traction -mu p v_T,c / s is -mu p P(e + du) / max(|P(e + du)|, d) (stick: an elastic
//   spring mu p / d; slip: mu p along the slip), the same terms with v_T,c and
//   dv_T,c/du = -(n . w_c) dn/du - n (w_c^T dn/du) + P dv_rel/du (w_c = v_rel + e / dt),
//   and the s^-3 term only while sliding (|v_T,c| > eps); the viscous part keeps v_T.
// Every term is tested against central finite differences of the force
// (tests/verification/contact_tangent_test.cpp).
//
// Units: mm, N, s.
#include <array>

#include "common/core/types.hpp"
#include "forming/contact/contact_law.hpp"

namespace sf::forming {

inline constexpr int kMaxPointFunctions = 32;  // 16 slave + 16 master

struct PointKinematics {
  int n = 0;                                              // local functions
  int n_slave = 0;                                        // the first n_slave are the slave face's
  std::array<double, kMaxPointFunctions> phi{};           // N_a, -M_b
  std::array<double, kMaxPointFunctions> rho1{}, rho2{};  // M_b,1, M_b,2 (0 on slave)
  double gap = 0.0;                                       // mm
  Vec3 normal = Vec3::UnitZ();                            // unit
  Vec3 gap_gradient = Vec3::UnitZ();                      // dg/dx_s (tool); = normal for a body
  bool tool = true;
  Mat3 dn_dx = Mat3::Zero();  // tool: d normal / d x_s, 1/mm
  // Body: the master's geometry at the foot point.
  Mat32 T = Mat32::Zero();
  Mat2 M_inv = Mat2::Zero(), H_inv = Mat2::Zero(), kappa = Mat2::Zero();
};

struct PointRates {
  bool have = false;              // no rates: friction gives nothing
  Vec3 relative = Vec3::Zero();   // v_rel, mm/s
  double inv_dt = 0.0;            // quasi-static: 1 / (t - t_prev); dynamic: 0
  Vec3 master_d1 = Vec3::Zero();  // m_1, m_2: d v_m / d zeta (body master only)
  Vec3 master_d2 = Vec3::Zero();
  // Slip-distance Coulomb (PointLaw::distance): the committed elastic slip over the step,
  // e / dt (mm/s), added to v_rel for the Coulomb term only (state: no derivative).
  Vec3 coulomb_shift = Vec3::Zero();
};

struct PointLaw {
  NormalResponse normal;
  double viscous = 0.0;         // c_f h(g): c_f where engaged, tapering to 0 (surface_contact.hpp)
  double viscous_slope = 0.0;   // d viscous / d g, N s/mm^4 (<= 0 in the taper, else 0)
  double coulomb = 0.0;         // mu
  double stick_velocity = 0.0;  // eps, mm/s (slip-distance form: the slip distance / dt)
  // Coulomb regularised by slip distance (FrictionLaw::stick_slip): the return map's
  // c = mu p / max(|v_T,c|, eps) on v_T,c = P (v_rel + shift), not mu p / sqrt(|v_T|^2 + eps^2).
  bool distance = false;
  bool friction() const { return viscous > 0.0 || coulomb > 0.0; }
};

// Local sums of the point contributions (sized by the caller: 3n, 3n x 3n).
//
// The stiffness of one point has rank at most 7 (body) or 3 (tool): with the 3n x 3
// matrix Phi = J^T (entries phi_a delta_ij), N_h = (H^-1 rho_a)_l n_i and R = rho_a,l
// (v_T)_i (3n x 2 each), every term above is Phi (.)^T, N_h (.)^T or R (.)^T, so
//   K_point = U V^T,  U = [Phi N_h R] (3n x 7),  V = the point's factors (3n x 7).
// add_contact_point() adds U V^T to `stiffness` at once, or, when defer_stiffness() was
// called, appends U and V as columns of `u` and `v` and finish_stiffness() adds them
// all in one matrix product (a pair block of 36 points: 3n x 3n x 252), which is
// what makes contact assembly cheap: no 3 x 3 block loop per point over the whole
// 3n x 3n matrix. Both give the same sums to round-off.
struct LocalContribution {
  double energy = 0.0;
  VecX force;
  MatX stiffness;  // empty: not wanted
  MatX damping;    // empty: not wanted
  // Deferred low-rank factors of the stiffness (columns 0 .. rank - 1 in use).
  MatX u, v;
  MatX lower, upper;  // scratch of the product
  int rank = 0;
  bool deferred = false;
  // Points to come (sizes the factors; more are allowed).
  void defer_stiffness(int points);
  // Adds the deferred factors U V^T to `stiffness` and empties them.
  void finish_stiffness();
};

// What the point carries (outputs, reactions).
struct PointState {
  double pressure = 0.0;          // MPa
  Vec3 slip_rate = Vec3::Zero();  // v_T, mm/s
  Vec3 shear = Vec3::Zero();      // friction traction on the slave, -c v_T, MPa
  Vec3 coulomb_slip_rate = Vec3::Zero();  // v_T,c (slip-distance form; = v_T otherwise), mm/s
};

PointState add_contact_point(const PointKinematics& k, const PointLaw& law, const PointRates& rates, double weight,
                             LocalContribution& out);

}  // namespace sf::forming
