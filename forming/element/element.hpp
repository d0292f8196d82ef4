#pragma once
// Total Lagrangian hyperelastic element kernels (principle of virtual work) for the
// ply elements, separate from the material law (forming/material/material.hpp) and from the
// mesh (the caller maps element xi-parameters to global dofs, forming/model/ply_mesh.hpp).
//
//   Brick  BicubicHermiteLinear: 32 functions, 3-D; element parameters X_e, x_e are
//          32 x 3 (row k = function k of common/basis/hermite.hpp, k = 4 n + d,
//          columns x, y, z), so X(xi) = sum_k N_k(xi) X_e.row(k).
//   Plane  CubicHermiteLinear (plane strain, unit depth): 8 functions, 2-D;
//          parameters 8 x 2 (x, y); F_33 = 1, the out-of-plane components are zero.
//
// Local element vector ordering: entry D k + i (function k, coordinate i < D), so the
// brick's force is 96 long and its tangent 96 x 96; the plane element's 16 and 16 x 16.
//
// At a Gauss point xi (weight w): G = dX/dxi (D x D), F = dx/dX = (dx/dxi) G^-1,
// C = F^T F, E = (C - I)/2, (S, CC) from the material, dV = w det G,
//   energy  = sum W dV
//   force   f_{ki} = sum P_iJ dN_k/dX_J dV,              P = F S
//   tangent K = sum (B^T CC B + G_geo) dV,
//           B: 6 x (D NF), Voigt rows (11, 22, 33, 2x12, 2x23, 2x13) of dE,
//              dE_IJ = sym(F^T dF)_IJ with dF = dx_k (x) dN_k/dX,
//           G_geo[(k,i),(l,j)] = delta_ij dN_k/dX . S dN_l/dX   (initial stress).
// The tangent is the exact derivative of the force (symmetric).
//
// Quadrature (default, ElementRule): 4 x 4 in-plane x 2 through the thickness for the
// brick, 4 x 2 for the plane element. Why: with an affine reference map the basis
// gradients are of degree <= 3 in each in-plane xi and <= 1 in xi3, so the
// small-strain stiffness integrand B^T D B is of degree <= 6 in-plane and <= 2
// through the thickness: 4-point and 2-point Gauss rules (exact to degree 7 and 3) are
// the smallest that integrate it exactly, i.e. full integration with no spurious zero-
// energy modes for any fibre angle and any stiffness ratio of the anisotropic law.
// (At finite strain the integrand is not polynomial; the rule is then the usual
// full-integration choice; a finer rule can be asked for.)
//
// Inverted points (det G <= 0 or det F <= 0) are a numerical outcome: the result's
// status says so and the caller (Newton) backs off; energy is +inf there.
//
// Constraint terms (optional, ConstraintTerms; default off = the plain kernel above):
// incompressibility J = 1 and fibre inextensibility I4 = 1 imposed on the ELEMENT MEAN
// with one multiplier per element and constraint (discontinuous, element-constant
// pressure p and fibre tension T, statically condensed: no global unknowns; Q1/P0 /
// mean-dilatation style). With V_e = integral of dV (reference volume, mm^3, D = 3;
// mm^2 per unit depth for the plane element) and a0 = material.fibre_direction():
//   g_J = (1/V_e) integral (J - 1) dV,          J = det F,
//   g_T = (1/V_e) integral (I4 - 1)/2 dV,       I4 = a0 . C a0 = |F a0|^2,
//   Pi_c = V_e [ -p g_J + kappa/2 g_J^2 ]        (if incompressible)
//        + V_e [  T g_T + k_fibre/2 g_T^2 ]      (if inextensible)
// is added to the element energy. SIGN CONVENTION (that of the notes, section 3.1, and
// of forming/material/material.hpp cauchy_stress): p is the PRESSURE (positive in
// compression), T the fibre TENSION (positive in tension); the element adds to S
//   -p_eff J C^-1 + T_eff a0 (x) a0,  i.e. sigma = -p_eff I + ... + (T_eff/J) a (x) a,
// with the effective (reported) multipliers
//   p_eff = p - kappa g_J,    T_eff = T + k_fibre g_T.
// With p = T = 0 this is the penalty / perturbed-Lagrangian form (kappa: bulk-like
// penalty, MPa; k_fibre: fibre penalty, MPa; expansion g_J > 0 gives p_eff < 0, i.e.
// tension). Augmented Lagrangian (Uzawa): after each converged solve set
//   p <- p_eff = p - kappa g_J,    T <- T_eff = T + k_fibre g_T
// (i.e. copy ElementResult::p_eff / T_eff back into the element's ConstraintTerms);
// this drives g_J, g_T -> 0 and p, T to the exact multipliers. NOTE the minus sign for
// p: it is the physical pressure, not the Lagrange multiplier of +g_J.
// Because only the element mean is constrained, a linear-through-thickness element
// can still bend (J - 1 and I4 - 1 vary through the thickness with zero mean), which
// avoids volumetric and fibre (extensional) locking; a pointwise penalty locks.
// Force and exact tangent (dg = dg/dx_e, d2g = d2g/dx_e^2, both integrals of
// per-point terms; n_k = F^-T dN_k/dX the spatial gradient, s_k = dN_k/dX . a0,
// a = F a0):
//   V_e dg_J/dx_{ki}       = integral J n_{k,i} dV
//   V_e d2g_J/dx_{ki}dx_{lj} = integral J (n_{k,i} n_{l,j} - n_{k,j} n_{l,i}) dV
//   V_e dg_T/dx_{ki}       = integral a_i s_k dV
//   V_e d2g_T/dx_{ki}dx_{lj} = integral delta_ij s_k s_l dV
//   force   += V_e (-p_eff dg_J + T_eff dg_T)
//   tangent += V_e (kappa dg_J dg_J^T - p_eff d2g_J + k_fibre dg_T dg_T^T + T_eff d2g_T)
// (a rank-one update per constraint plus the multiplier-weighted second derivative;
// still symmetric and the exact derivative of the force). The plane element uses the
// same formulas with F_33 = 1 (a0 may have a z component; it enters I4 as a constant).
// With the incompressible TransverselyIsotropic law the reference state is stress free
// at p = mu_T (forming/material/transversely_isotropic.hpp), so start the Uzawa loop
// from p = mu_T there.
// CAUTION (measured in tests/forming/constraint_test.cpp, ConstraintLocking): only the
// element mean of J is constrained, so the zero-mean part of the dilatation is resisted
// by the material alone. The incompressible law has no volumetric energy, and with
// p = mu_T its linearised effective Lame constant is -mu_T (bulk -mu_T/3): one linear
// layer through the thickness then bends with E_b = mu_T in plane strain (1/4 of the
// exact 4 mu_T) and has an almost zero-energy synclastic bending mode with a free
// width. Use a base law with positive pointwise bulk modulus (compressible ply law,
// lambda > 0) and let the mean constraint drive the mean J to 1; one linear layer then
// bends with E_b = lambda + 2 mu_T (plane strain; eps33 is constant through it).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/quadrature/gauss.hpp"
#include "forming/material/material.hpp"

namespace sf::forming {

// Gauss points per direction.
struct ElementRule {
  int n_inplane = 4;    // per in-plane direction (xi1, xi2; xi1 for the plane element)
  int n_thickness = 2;  // through the thickness (xi3; xi2 for the plane element)
  // Throws sf::InputError naming the field when a count is outside [1, 32].
  void validate() const;
  quadrature::TensorRule<3> brick() const;
  quadrature::TensorRule<2> plane() const;
};

// Element-mean constraint terms (see header). Units: kappa, k_fibre, p, T in MPa.
struct ConstraintTerms {
  bool incompressible = false;  // add the J = 1 (mean) term
  double kappa = 0.0;           // volumetric penalty, MPa (>= 0)
  double p = 0.0;               // element pressure multiplier, MPa (positive = compression)
  bool inextensible = false;    // add the I4 = 1 (mean) term
  double k_fibre = 0.0;         // fibre penalty, MPa (>= 0)
  double T = 0.0;               // element fibre-tension multiplier, MPa (positive = tension)
  bool active() const { return incompressible || inextensible; }
  // Throws sf::InputError naming the field when a penalty is negative or a value not
  // finite.
  void validate() const;
};

struct ElementResult {
  enum class Status {
    kOk,
    kInvertedReference,  // det G <= 0 at a Gauss point: bad reference geometry
    kInverted,           // det F <= 0 at a Gauss point: the current state is not admissible
  };
  Status status = Status::kOk;
  double energy = 0.0;     // N mm (= integral of W over the element)
  VecX force;              // D NF, N (internal force, dE/dx)
  MatX tangent;            // D NF x D NF, N/mm (empty unless asked for)
  double min_det_f = 0.0;  // smallest det F over the Gauss points
  // Constraint terms (zero unless ConstraintTerms::active(); the energy, force and
  // tangent above already include them):
  double volume = 0.0;             // V_e = integral of dV, mm^3 (mm^2 for the plane element)
  double g_J = 0.0;                // element mean of J - 1 (computed whenever active)
  double g_T = 0.0;                // element mean of (I4 - 1)/2 (computed whenever active)
  double p_eff = 0.0;              // p - kappa g_J, MPa (incompressible), the Uzawa update
  double T_eff = 0.0;              // T + k_fibre g_T, MPa (inextensible), the Uzawa update
  double constraint_energy = 0.0;  // Pi_c, N mm (part of energy)
  bool ok() const { return status == Status::kOk; }
};

using BrickParams = Eigen::Matrix<double, 32, 3>;
using PlaneParams = Eigen::Matrix<double, 8, 2>;

// Brick element: reference and current xi-parameters (32 x 3, mm). `constraints`
// (default: none) adds the element-mean constraint terms; it is validated, and
// inextensibility with a material without a fibre direction throws sf::InputError.
ElementResult brick_element(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                            const quadrature::TensorRule<3>& rule, bool want_tangent,
                            const ConstraintTerms& constraints = ConstraintTerms{});
// Plane-strain element (per unit depth: energy N mm/mm, force N/mm).
ElementResult plane_element(const PlaneParams& X_e, const PlaneParams& x_e, const Material& material,
                            const quadrature::TensorRule<2>& rule, bool want_tangent,
                            const ConstraintTerms& constraints = ConstraintTerms{});

// The brick kernel as the model's assembly runs it: the basis derivatives at the rule's
// points are computed once, and each call reuses the caller's buffers (no allocation
// once `out` and `scratch` have their sizes). Same results as brick_element() up to
// rounding.
//
// How the tangent is computed (and why it is fast): the material part is
//   K_mat = sum_q B_q^T (dV_q CC_q B_q),  B_q: 6 x 96 (the header's B, columns in the
// header's order D k + i), one product A^T B with A = [B_1; ...; B_Q] and
// B = [dV CC B_1; ...] of depth 6 Q, of which only the lower triangle is formed, straight
// into out.tangent (linalg::set_atb_lower, register-blocked and compiled for AVX-512,
// AVX2 + FMA and SSE2, chosen at run time: linalg::kernel_isa()). B and dV CC B are formed
// together in vector registers, along the header's order (the coordinate of a column
// repeats with period 3, so F's entries per lane repeat every 24 columns). The
// initial-stress part is one 32 x 32 product of depth 3 Q added to the three diagonal
// coordinate blocks; the lower triangle is then copied to the upper one in 8 x 8 tiles.
struct BrickScratch {
  std::vector<double> b, d, ga, gb, k_mat, k_geo, gh;
};

class BrickKernel {
 public:
  explicit BrickKernel(const quadrature::TensorRule<3>& rule);
  int n_points() const { return static_cast<int>(weights_.size()); }
  // As brick_element(X_e, x_e, material, rule, want_tangent, constraints), into `out`.
  void evaluate(const BrickParams& X_e, const BrickParams& x_e, const Material& material, bool want_tangent,
                const ConstraintTerms& constraints, BrickScratch& scratch, ElementResult& out) const;
  // Floating-point operations of one evaluation with the tangent (counted from the
  // algorithm: products, B and dV CC B, kinematics and force; not the material law).
  double tangent_flops() const;
  // ... and of one evaluation without it.
  double force_flops() const;

 private:
  std::vector<double> weights_;
  std::vector<double> dxi_;   // per point 3 x 32: dN_k/dxi_a at [96 q + 32 a + k]
  std::vector<double> dxi3_;  // the same in the header's order: dN_k/dxi_a at [288 q + 96 a + 3 k + i]
  std::vector<double> dxit_;  // all points' as 32 rows: dN_k/dxi_a at [ld_ k + 3 q + a]
  int ld_ = 0;                // 3 n_points rounded up to a multiple of 32
};

// The straightforward per-point implementation (B^T CC B over the full 96 x 96 at each
// Gauss point); what the tests check BrickKernel against.
ElementResult brick_element_reference(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                                      const quadrature::TensorRule<3>& rule, bool want_tangent,
                                      const ConstraintTerms& constraints = ConstraintTerms{});

// Deformation gradient at every point of the rule (order of rule.points); the plane
// element's F is embedded in 3 x 3 with F_33 = 1.
std::vector<Mat3> brick_deformation_gradients(const BrickParams& X_e, const BrickParams& x_e,
                                              const quadrature::TensorRule<3>& rule);
std::vector<Mat3> plane_deformation_gradients(const PlaneParams& X_e, const PlaneParams& x_e,
                                              const quadrature::TensorRule<2>& rule);

std::string to_string(ElementResult::Status status);

}  // namespace sf::forming
