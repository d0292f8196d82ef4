#include "forming/element/element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/linalg/dense_kernels.hpp"
#include "common/linalg/simd.hpp"

namespace sf::forming {
namespace {

// Voigt rows (11, 22, 33, 12, 23, 13) as index pairs.
constexpr int kVoigtPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

// Gradients with respect to X of the NF functions at one point, padded to 3 columns
// (zero for directions the element does not have), and the point's det G.
template <class Basis, int D>
struct PointGeometry {
  Eigen::Matrix<double, Basis::kNumFunctions, 3> dn_dX;
  double det_g = 0.0;
};

template <class Basis, int D>
PointGeometry<Basis, D> point_geometry(const Eigen::Matrix<double, Basis::kNumFunctions, D>& X_e,
                                       const Eigen::Matrix<double, D, 1>& xi) {
  const auto values = Basis::evaluate(xi, basis::kFirst);
  const Eigen::Matrix<double, D, D> G = X_e.transpose() * values.first;  // G(i, a) = dX_i/dxi_a
  PointGeometry<Basis, D> pg;
  pg.det_g = G.determinant();
  pg.dn_dX.setZero();
  if (pg.det_g > 0.0) pg.dn_dX.template leftCols<D>() = values.first * G.inverse();
  return pg;
}

template <class Basis, int D>
Mat3 deformation_gradient(const Eigen::Matrix<double, Basis::kNumFunctions, D>& x_e,
                          const Eigen::Matrix<double, Basis::kNumFunctions, 3>& dn_dX) {
  Mat3 F = Mat3::Identity();
  F.topLeftCorner<D, D>() = x_e.transpose() * dn_dX.template leftCols<D>();
  return F;
}

// Running integrals of the element-mean constraints (element.hpp header): the
// reference volume, V_e g, V_e dg/dx and (with the tangent) V_e d2g/dx2.
template <int NF, int D>
struct ConstraintAccumulator {
  static constexpr int ND = D * NF;
  bool incompressible = false, inextensible = false, want_tangent = false;
  Vec3 a0 = Vec3::Zero();
  double volume = 0.0;
  double int_j = 0.0, int_t = 0.0;  // integrals of J - 1 and (I4 - 1)/2
  Eigen::Matrix<double, ND, 1> grad_j = Eigen::Matrix<double, ND, 1>::Zero();
  Eigen::Matrix<double, ND, 1> grad_t = Eigen::Matrix<double, ND, 1>::Zero();
  MatX hess_j;                                                                      // ND x ND
  Eigen::Matrix<double, NF, NF> hess_t_ss = Eigen::Matrix<double, NF, NF>::Zero();  // integral s s^T

  ConstraintAccumulator(const ConstraintTerms& c, const Vec3& fibre, bool tangent)
      : incompressible(c.incompressible), inextensible(c.inextensible), want_tangent(tangent), a0(fibre) {
    if (incompressible && want_tangent) hess_j = MatX::Zero(ND, ND);
  }

  void add_point(const Mat3& F, double det_f, const Eigen::Matrix<double, NF, 3>& dn_dX, double dv) {
    volume += dv;
    if (incompressible) {
      int_j += (det_f - 1.0) * dv;
      const Mat3 f_inv = F.inverse();
      // n(k, i) = dN_k/dx_i = sum_J dN_k/dX_J Finv_Ji.
      const Eigen::Matrix<double, NF, 3> n = dn_dX * f_inv;
      const double w = dv * det_f;
      for (int k = 0; k < NF; ++k)
        for (int i = 0; i < D; ++i) grad_j(D * k + i) += w * n(k, i);
      if (want_tangent) {
        for (int l = 0; l < NF; ++l)
          for (int j = 0; j < D; ++j)
            for (int k = 0; k < NF; ++k)
              for (int i = 0; i < D; ++i) hess_j(D * k + i, D * l + j) += w * (n(k, i) * n(l, j) - n(k, j) * n(l, i));
      }
    }
    if (inextensible) {
      const Vec3 a = F * a0;
      int_t += 0.5 * (a.squaredNorm() - 1.0) * dv;
      const Eigen::Matrix<double, NF, 1> s = dn_dX * a0;  // s_k = dN_k/dX . a0
      for (int k = 0; k < NF; ++k)
        for (int i = 0; i < D; ++i) grad_t(D * k + i) += dv * a(i) * s(k);
      if (want_tangent) hess_t_ss.noalias() += dv * (s * s.transpose());
    }
  }

  // Adds Pi_c and its derivatives to r and fills the constraint fields.
  void finish(const ConstraintTerms& c, ElementResult& r) const {
    r.volume = volume;
    double pi = 0.0;
    if (incompressible) {
      r.g_J = int_j / volume;
      r.p_eff = c.p - c.kappa * r.g_J;
      pi += volume * (-c.p * r.g_J + 0.5 * c.kappa * r.g_J * r.g_J);
      r.force.noalias() -= r.p_eff * grad_j;  // grad_j = V_e dg_J/dx
      if (want_tangent) {
        r.tangent.noalias() += (c.kappa / volume) * (grad_j * grad_j.transpose());
        r.tangent.noalias() -= r.p_eff * hess_j;
      }
    }
    if (inextensible) {
      r.g_T = int_t / volume;
      r.T_eff = c.T + c.k_fibre * r.g_T;
      pi += volume * (c.T * r.g_T + 0.5 * c.k_fibre * r.g_T * r.g_T);
      r.force.noalias() += r.T_eff * grad_t;
      if (want_tangent) {
        r.tangent.noalias() += (c.k_fibre / volume) * (grad_t * grad_t.transpose());
        for (int l = 0; l < NF; ++l)
          for (int k = 0; k < NF; ++k)
            for (int i = 0; i < D; ++i) r.tangent(D * k + i, D * l + i) += r.T_eff * hess_t_ss(k, l);
      }
    }
    r.constraint_energy = pi;
    r.energy += pi;
  }
};

template <class Basis, int D>
ElementResult integrate(const Eigen::Matrix<double, Basis::kNumFunctions, D>& X_e,
                        const Eigen::Matrix<double, Basis::kNumFunctions, D>& x_e, const Material& material,
                        const quadrature::TensorRule<D>& rule, bool want_tangent, const ConstraintTerms& constraints) {
  constexpr int NF = Basis::kNumFunctions;
  constexpr int ND = D * NF;
  constraints.validate();
  const Vec3 a0 = material.fibre_direction();
  if (constraints.inextensible && !(a0.norm() > 0.0))
    throw InputError("constraint terms: fibre inextensibility needs a material with a fibre direction (" +
                     material.name() + " has none)");
  ElementResult r;
  r.force = VecX::Zero(ND);
  if (want_tangent) r.tangent = MatX::Zero(ND, ND);
  r.min_det_f = std::numeric_limits<double>::infinity();
  const bool constrained = constraints.active();
  ConstraintAccumulator<NF, D> acc(constraints, a0, want_tangent && constrained);
  Eigen::Matrix<double, 6, ND> B;
  for (int q = 0; q < rule.size(); ++q) {
    const PointGeometry<Basis, D> pg = point_geometry<Basis, D>(X_e, rule.points[q]);
    if (!(pg.det_g > 0.0)) {
      r.status = ElementResult::Status::kInvertedReference;
      r.energy = std::numeric_limits<double>::infinity();
      return r;
    }
    const Mat3 F = deformation_gradient<Basis, D>(x_e, pg.dn_dX);
    const double det_f = F.determinant();
    r.min_det_f = std::min(r.min_det_f, det_f);
    if (!(det_f > 0.0)) {
      r.status = ElementResult::Status::kInverted;
      r.energy = std::numeric_limits<double>::infinity();
      return r;
    }
    const Mat3 C = F.transpose() * F;
    const MaterialResponse resp = material.evaluate(C, want_tangent);
    const double dv = rule.weights[q] * pg.det_g;
    r.energy += resp.energy * dv;
    if (constrained) acc.add_point(F, det_f, pg.dn_dX, dv);
    const Mat3 P = F * resp.stress;
    // f_{ki} = P_iJ dN_k/dX_J dV
    const Eigen::Matrix<double, NF, 3> pn = pg.dn_dX * P.transpose();  // (k, i) = sum_J dN_k/dX_J P_iJ
    for (int k = 0; k < NF; ++k)
      for (int i = 0; i < D; ++i) r.force(D * k + i) += dv * pn(k, i);
    if (!want_tangent) continue;
    // B: dE (Voigt, doubled shears) = B dx_e.
    for (int k = 0; k < NF; ++k) {
      const Eigen::RowVector3d g = pg.dn_dX.row(k);
      for (int i = 0; i < D; ++i) {
        const int col = D * k + i;
        for (int I = 0; I < 6; ++I) {
          const int a = kVoigtPair[I][0], b = kVoigtPair[I][1];
          B(I, col) = a == b ? F(i, a) * g(a) : F(i, a) * g(b) + F(i, b) * g(a);
        }
      }
    }
    const Eigen::Matrix<double, 6, ND> cb = resp.tangent * B;
    r.tangent.noalias() += dv * (B.transpose() * cb);
    // Initial stress: delta_ij dN_k/dX . S dN_l/dX.
    const Eigen::Matrix<double, NF, 3> sn = pg.dn_dX * resp.stress;  // S symmetric
    const Eigen::Matrix<double, NF, NF> geo = sn * pg.dn_dX.transpose();
    for (int k = 0; k < NF; ++k)
      for (int l = 0; l < NF; ++l)
        for (int i = 0; i < D; ++i) r.tangent(D * k + i, D * l + i) += dv * geo(k, l);
  }
  if (constrained) acc.finish(constraints, r);
  return r;
}

template <class Basis, int D>
std::vector<Mat3> gradients(const Eigen::Matrix<double, Basis::kNumFunctions, D>& X_e,
                            const Eigen::Matrix<double, Basis::kNumFunctions, D>& x_e,
                            const quadrature::TensorRule<D>& rule) {
  std::vector<Mat3> out;
  out.reserve(rule.size());
  for (int q = 0; q < rule.size(); ++q) {
    const PointGeometry<Basis, D> pg = point_geometry<Basis, D>(X_e, rule.points[q]);
    out.push_back(pg.det_g > 0.0 ? deformation_gradient<Basis, D>(x_e, pg.dn_dX)
                                 : Mat3::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  return out;
}

// ---------------------------------------------------------------------------------
// BrickKernel: per-point pieces written once over the vector width W (doubles per
// register) and compiled per instruction set (common/linalg/simd.hpp).

constexpr int kNf = 32;       // brick functions
constexpr int kNd = 3 * kNf;  // element dofs

// dX/dxi and dx/dxi at every point at once: gh[ld r + 3 q + a] = sum_k P(k, i) dN_k/dxi_a
// at point q, with P = X for rows r = i < 3 and P = x for rows r = 3 + i. dxit holds the
// basis derivatives as 32 rows of ld entries (dxit[ld k + 3 q + a]); ld is a multiple of 32
// (whole blocks of vectors; the padding is zero). Vectorised along the points, so no
// horizontal sums.
template <int W>
[[gnu::always_inline]] inline void element_jacobians(const double* dxit, int ld, const double* X, const double* x,
                                                     double* gh) {
  using V = linalg::simd::Vec<W>;
  using linalg::simd::at;
  constexpr int kNb = W == 8 ? 4 : 2;  // vectors of columns at once: 6 kNb accumulators
  for (int c = 0; c < ld; c += kNb * W) {
    V acc[6][kNb];
    for (int r = 0; r < 6; ++r)
      for (int v = 0; v < kNb; ++v) acc[r][v] = V{};
    for (int k = 0; k < kNf; ++k) {
      V d[kNb];
      for (int v = 0; v < kNb; ++v) d[v] = at<W>(dxit + static_cast<long>(ld) * k + c + v * W);
      for (int i = 0; i < 3; ++i) {
        const double Xi = X[kNf * i + k], xi = x[kNf * i + k];
        for (int v = 0; v < kNb; ++v) {
          acc[i][v] += d[v] * Xi;
          acc[3 + i][v] += d[v] * xi;
        }
      }
    }
    for (int r = 0; r < 6; ++r)
      for (int v = 0; v < kNb; ++v) at<W>(gh + static_cast<long>(ld) * r + c + v * W) = acc[r][v];
  }
}

// Geometry and deformation at one point from its columns of element_jacobians (gh points
// at column 3 q, rows ld apart): G = dX/dxi, g^T = G^-T (dN/dxi)^T (3 x 32,
// gt[32 A + k] = dN_k/dX_A), the same in the header's order (g3, 3 x 96) and
// F = (dx/dxi) G^-1 (row-major, F[3 i + A]). Returns det G (the rest is unset when it is
// not positive).
template <int W>
[[gnu::always_inline]] inline double point_kinematics(const double* dxi, const double* dxi3, const double* gh, int ld,
                                                      double* gt, double* g3, double* F) {
  using V = linalg::simd::Vec<W>;
  using linalg::simd::at;
  double G[3][3], H[3][3];
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) {
      G[i][a] = gh[static_cast<long>(ld) * i + a];
      H[i][a] = gh[static_cast<long>(ld) * (3 + i) + a];
    }
  const double c00 = G[1][1] * G[2][2] - G[1][2] * G[2][1];
  const double c01 = G[1][2] * G[2][0] - G[1][0] * G[2][2];
  const double c02 = G[1][0] * G[2][1] - G[1][1] * G[2][0];
  const double det = G[0][0] * c00 + G[0][1] * c01 + G[0][2] * c02;
  if (!(det > 0.0)) return det;
  // inv(a, A) = (G^-1)(a, A) = cofactor(A, a) / det
  double inv[3][3];
  inv[0][0] = c00 / det;
  inv[1][0] = c01 / det;
  inv[2][0] = c02 / det;
  inv[0][1] = (G[0][2] * G[2][1] - G[0][1] * G[2][2]) / det;
  inv[1][1] = (G[0][0] * G[2][2] - G[0][2] * G[2][0]) / det;
  inv[2][1] = (G[0][1] * G[2][0] - G[0][0] * G[2][1]) / det;
  inv[0][2] = (G[0][1] * G[1][2] - G[0][2] * G[1][1]) / det;
  inv[1][2] = (G[0][2] * G[1][0] - G[0][0] * G[1][2]) / det;
  inv[2][2] = (G[0][0] * G[1][1] - G[0][1] * G[1][0]) / det;
  // dN_k/dX_A = sum_a dN_k/dxi_a inv(a, A)
  for (int k = 0; k < kNf; k += W) {
    const V d0 = at<W>(dxi + k), d1 = at<W>(dxi + kNf + k), d2 = at<W>(dxi + 2 * kNf + k);
    for (int A = 0; A < 3; ++A) at<W>(gt + kNf * A + k) = d0 * inv[0][A] + d1 * inv[1][A] + d2 * inv[2][A];
  }
  // The same gradients in the header's order c = 3 k + i (each function's three times), so
  // that the force and the B rows come out in the order of the result: the same
  // operations on the same numbers, so the same bits as gt.
  for (int c = 0; c < kNd; c += W) {
    const V d0 = at<W>(dxi3 + c), d1 = at<W>(dxi3 + kNd + c), d2 = at<W>(dxi3 + 2 * kNd + c);
    for (int A = 0; A < 3; ++A) at<W>(g3 + kNd * A + c) = d0 * inv[0][A] + d1 * inv[1][A] + d2 * inv[2][A];
  }
  for (int i = 0; i < 3; ++i)
    for (int A = 0; A < 3; ++A) F[3 * i + A] = H[i][0] * inv[0][A] + H[i][1] * inv[1][A] + H[i][2] * inv[2][A];
  return det;
}

// Force (in the header's order, f[3 k + i] += dV sum_A P_iA dN_k/dX_A, P = F S) and, with
// `tangent`, the point's rows of the two products: b (6 x 96, B in Voigt rows, columns in
// the header's order 3 k + i), d (6 x 96, dV CC B), ga (3 x 32, dN/dX) and gb (3 x 32,
// dV S dN/dX), point q's rows 6 q .. 6 q + 5 (3 q .. 3 q + 2) of the products' operands of
// depth 6 nq (3 nq), stored packed (linalg::packed_index). g3 is dN/dX in the header's
// order (3 x 96, g3[96 A + 3 k + i] = dN_k/dX_A).
// F, S, P row-major; CC row-major 6 x 6. Along the header's order the coordinate i of a
// column repeats with period 3, so F's and P's entries per lane repeat every 24 columns
// (a whole number of vectors for every width).
template <int W>
[[gnu::always_inline]] inline void point_rows(const double* gt, const double* g3, const double* F, const double* S,
                                              const double* CC, double dv, bool tangent, int q, int nq, double* f,
                                              double* b, double* d, double* ga, double* gb) {
  using V = linalg::simd::Vec<W>;
  using linalg::simd::at;
  constexpr int kPeriod = 24;
  static_assert(kPeriod % W == 0 && kNd % kPeriod == 0, "lane patterns must tile the columns");
  double P[9];
  for (int i = 0; i < 3; ++i)
    for (int A = 0; A < 3; ++A)
      P[3 * i + A] = dv * (F[3 * i] * S[A] + F[3 * i + 1] * S[3 + A] + F[3 * i + 2] * S[6 + A]);
  alignas(64) double pp[3][kPeriod], fp[3][kPeriod];  // [A][c] = P or F at (c % 3, A)
  for (int c = 0; c < kPeriod; ++c)
    for (int A = 0; A < 3; ++A) {
      pp[A][c] = P[3 * (c % 3) + A];
      fp[A][c] = F[3 * (c % 3) + A];
    }
  for (int c = 0; c < kNd; c += W) {
    const V g0 = at<W>(g3 + c), g1 = at<W>(g3 + kNd + c), g2 = at<W>(g3 + 2 * kNd + c);
    const int m = c % kPeriod;
    at<W>(f + c) += g0 * at<W>(pp[0] + m) + g1 * at<W>(pp[1] + m) + g2 * at<W>(pp[2] + m);
  }
  if (!tangent) return;
  double cc[36];
  for (int I = 0; I < 36; ++I) cc[I] = dv * CC[I];
  for (int c = 0; c < kNd; c += W) {
    const V g0 = at<W>(g3 + c), g1 = at<W>(g3 + kNd + c), g2 = at<W>(g3 + 2 * kNd + c);
    const int m = c % kPeriod;
    const V f0 = at<W>(fp[0] + m), f1 = at<W>(fp[1] + m), f2 = at<W>(fp[2] + m);
    V bv[6];
    bv[0] = g0 * f0;
    bv[1] = g1 * f1;
    bv[2] = g2 * f2;
    bv[3] = g1 * f0 + g0 * f1;
    bv[4] = g2 * f1 + g1 * f2;
    bv[5] = g2 * f0 + g0 * f2;
    for (int I = 0; I < 6; ++I) {
      const long at_p = linalg::packed_index(6 * nq, 6 * q + I, c);
      at<W>(b + at_p) = bv[I];
      V s = bv[0] * cc[6 * I];
      for (int J = 1; J < 6; ++J) s += bv[J] * cc[6 * I + J];
      at<W>(d + at_p) = s;
    }
  }
  for (int k = 0; k < kNf; k += W) {
    const V g0 = at<W>(gt + k), g1 = at<W>(gt + kNf + k), g2 = at<W>(gt + 2 * kNf + k);
    for (int A = 0; A < 3; ++A) {
      const long at_p = linalg::packed_index(3 * nq, 3 * q + A, k);
      at<W>(ga + at_p) = A == 0 ? g0 : (A == 1 ? g1 : g2);
      at<W>(gb + at_p) = (g0 * S[3 * A] + g1 * S[3 * A + 1] + g2 * S[3 * A + 2]) * dv;
    }
  }
}

#define SF_BRICK_KERNEL_VARIANTS(attr, suffix, W)                                                              \
  attr void element_jacobians_##suffix(const double* dxit, int ld, const double* X, const double* x,           \
                                       double* gh) {                                                           \
    element_jacobians<W>(dxit, ld, X, x, gh);                                                                  \
  }                                                                                                            \
  attr double point_kinematics_##suffix(const double* dxi, const double* dxi3, const double* gh, int ld,       \
                                        double* gt, double* g3, double* F) {                                   \
    return point_kinematics<W>(dxi, dxi3, gh, ld, gt, g3, F);                                                  \
  }                                                                                                            \
  attr void point_rows_##suffix(const double* gt, const double* g3, const double* F, const double* S,          \
                                const double* CC, double dv, bool tangent, int q, int nq, double* f,          \
                                double* b, double* d, double* ga, double* gb) {                                 \
    point_rows<W>(gt, g3, F, S, CC, dv, tangent, q, nq, f, b, d, ga, gb);                                       \
  }
SF_BRICK_KERNEL_VARIANTS(SF_SIMD_AVX512, avx512, 8)
SF_BRICK_KERNEL_VARIANTS(SF_SIMD_AVX2, avx2, 4)
SF_BRICK_KERNEL_VARIANTS(, generic, 2)
#undef SF_BRICK_KERNEL_VARIANTS

using JacobiansFn = void (*)(const double*, int, const double*, const double*, double*);
using KinematicsFn = double (*)(const double*, const double*, const double*, int, double*, double*, double*);
using RowsFn = void (*)(const double*, const double*, const double*, const double*, const double*, double, bool, int,
                        int, double*, double*, double*, double*, double*);

void pick_variants(JacobiansFn& jac, KinematicsFn& kin, RowsFn& rows) {
  switch (linalg::kernel_isa()) {
    case linalg::KernelIsa::kAvx512:
      jac = element_jacobians_avx512;
      kin = point_kinematics_avx512;
      rows = point_rows_avx512;
      return;
    case linalg::KernelIsa::kAvx2:
      jac = element_jacobians_avx2;
      kin = point_kinematics_avx2;
      rows = point_rows_avx2;
      return;
    case linalg::KernelIsa::kGeneric:
      break;
  }
  jac = element_jacobians_generic;
  kin = point_kinematics_generic;
  rows = point_rows_generic;
}

}  // namespace

BrickKernel::BrickKernel(const quadrature::TensorRule<3>& rule) : weights_(rule.weights) {
  dxi_.resize(static_cast<std::size_t>(3 * kNf * rule.size()));
  for (int q = 0; q < rule.size(); ++q) {
    const auto values = basis::BicubicHermiteLinear::evaluate(rule.points[q], basis::kFirst);
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < kNf; ++k) dxi_[static_cast<std::size_t>(3 * kNf * q + kNf * a + k)] = values.first(k, a);
  }
  ld_ = (3 * rule.size() + 31) / 32 * 32;
  dxit_.assign(static_cast<std::size_t>(kNf * ld_), 0.0);
  for (int q = 0; q < rule.size(); ++q)
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < kNf; ++k)
        dxit_[static_cast<std::size_t>(ld_ * k + 3 * q + a)] = dxi_[static_cast<std::size_t>(3 * kNf * q + kNf * a + k)];
  dxi3_.resize(static_cast<std::size_t>(3 * kNd * rule.size()));
  for (int q = 0; q < rule.size(); ++q)
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < kNd; ++c)
        dxi3_[static_cast<std::size_t>(3 * kNd * q + kNd * a + c)] =
            dxi_[static_cast<std::size_t>(3 * kNf * q + kNf * a + c / 3)];
}

double BrickKernel::force_flops() const {
  // dX/dxi and dx/dxi (18 dot products of 32), F = dx/dxi G^-1 (45), dN/dX (9 axpy of 32),
  // P (54), force (9 axpy of 32).
  return n_points() * (18.0 * 2 * kNf + 45.0 + 9.0 * 2 * kNf + 54.0 + 9.0 * 2 * kNf);
}

double BrickKernel::tangent_flops() const {
  const int nq = n_points();
  // B (12 flops per column) and dV CC B (66 per column and Voigt row block of 6 rows:
  // 6 x 11), dV S dN/dX (3 x 3 x 2 per function + scale), then the two products.
  const double rows = nq * (kNd * (12.0 + 66.0) + kNf * 3.0 * 7.0);
  return force_flops() + rows + linalg::add_atb_lower_flops(kNd, 6 * nq) + linalg::add_atb_lower_flops(kNf, 3 * nq);
}

void BrickKernel::evaluate(const BrickParams& X_e, const BrickParams& x_e, const Material& material, bool want_tangent,
                           const ConstraintTerms& constraints, BrickScratch& scratch, ElementResult& out) const {
  constraints.validate();
  const Vec3 a0 = material.fibre_direction();
  if (constraints.inextensible && !(a0.norm() > 0.0))
    throw InputError("constraint terms: fibre inextensibility needs a material with a fibre direction (" +
                     material.name() + " has none)");
  const int nq = n_points();
  out.status = ElementResult::Status::kOk;
  out.energy = 0.0;
  out.min_det_f = std::numeric_limits<double>::infinity();
  out.volume = out.g_J = out.g_T = out.p_eff = out.T_eff = out.constraint_energy = 0.0;
  JacobiansFn jacobians = nullptr;
  KinematicsFn kinematics = nullptr;
  RowsFn rows = nullptr;
  pick_variants(jacobians, kinematics, rows);

  // Buffers start on a 64-byte boundary (a cache line, one AVX-512 vector): the products'
  // row loads then never straddle two lines.
  auto aligned = [](std::vector<double>& v, std::size_t n) {
    if (v.size() != n + 8) v.assign(n + 8, 0.0);
    const auto misalign = reinterpret_cast<std::uintptr_t>(v.data()) % 64;
    return v.data() + (misalign == 0 ? 0 : (64 - misalign) / sizeof(double));
  };
  const std::size_t nq6 = static_cast<std::size_t>(6 * nq), nq3 = static_cast<std::size_t>(3 * nq);
  double *b = nullptr, *d = nullptr, *ga = nullptr, *gb = nullptr;
  if (want_tangent) {
    b = aligned(scratch.b, nq6 * kNd);
    d = aligned(scratch.d, nq6 * kNd);
    ga = aligned(scratch.ga, nq3 * kNf);
    gb = aligned(scratch.gb, nq3 * kNf);
  }
  // The force in the header's order, accumulated over the points.
  alignas(64) double f[kNd] = {};
  alignas(64) double gt[3 * kNf];
  alignas(64) double g3[3 * kNd];
  const bool constrained = constraints.active();
  ConstraintAccumulator<kNf, 3> acc(constraints, a0, want_tangent && constrained);
  Eigen::Matrix<double, kNf, 3> dn_dX;
  double* gh = aligned(scratch.gh, static_cast<std::size_t>(6 * ld_));
  jacobians(dxit_.data(), ld_, X_e.data(), x_e.data(), gh);
  for (int q = 0; q < nq; ++q) {
    double F[9];
    const double det_g = kinematics(&dxi_[static_cast<std::size_t>(3 * kNf * q)],
                                    &dxi3_[static_cast<std::size_t>(3 * kNd * q)], gh + 3 * q, ld_, gt, g3, F);
    if (!(det_g > 0.0)) {
      out.status = ElementResult::Status::kInvertedReference;
      out.energy = std::numeric_limits<double>::infinity();
      return;
    }
    Mat3 Fm;
    Fm << F[0], F[1], F[2], F[3], F[4], F[5], F[6], F[7], F[8];
    const double det_f = Fm.determinant();
    out.min_det_f = std::min(out.min_det_f, det_f);
    if (!(det_f > 0.0)) {
      out.status = ElementResult::Status::kInverted;
      out.energy = std::numeric_limits<double>::infinity();
      return;
    }
    const MaterialResponse resp = material.evaluate(Fm.transpose() * Fm, want_tangent);
    const double dv = weights_[static_cast<std::size_t>(q)] * det_g;
    out.energy += resp.energy * dv;
    // Row-major copies of S and CC for the vector code.
    double S[9], CC[36];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) S[3 * i + j] = resp.stress(i, j);
    if (want_tangent)
      for (int I = 0; I < 6; ++I)
        for (int J = 0; J < 6; ++J) CC[6 * I + J] = resp.tangent(I, J);
    rows(gt, g3, F, S, CC, dv, want_tangent, q, nq, f, b, d, ga, gb);
    if (constrained) {
      for (int A = 0; A < 3; ++A)
        for (int k = 0; k < kNf; ++k) dn_dX(k, A) = gt[kNf * A + k];
      acc.add_point(Fm, det_f, dn_dX, dv);
    }
  }
  if (out.force.size() != kNd) out.force.resize(kNd);
  std::copy(f, f + kNd, out.force.data());
  if (want_tangent) {
    if (out.tangent.rows() != kNd || out.tangent.cols() != kNd) out.tangent.resize(kNd, kNd);
    double* t = out.tangent.data();
    double* kg = aligned(scratch.k_geo, static_cast<std::size_t>(kNf * kNf));
    // The material part straight into the result's lower triangle (the rows of b and d
    // are in the header's order already), the initial-stress part into its own 32 x 32.
    linalg::set_atb_lower_packed(kNd, 6 * nq, b, d, t, kNd);
    linalg::set_atb_lower_packed(kNf, 3 * nq, ga, gb, kg, kNf);
    // Initial stress on the diagonal coordinate blocks: K(3 k + i, 3 l + i) += kg(k, l),
    // k >= l (lower triangle).
    for (int l = 0; l < kNf; ++l)
      for (int i = 0; i < 3; ++i) {
        double* col = t + kNd * (3 * l + i) + i;
        const double* kgl = kg + kNf * l;
        for (int k = l; k < kNf; ++k) col[3 * k] += kgl[k];
      }
    // Lower triangle to the upper one, in 8 x 8 tiles (both tiles stay in the L1 cache;
    // fixed bounds off the diagonal, so the copies unroll).
    static_assert(kNd % 8 == 0, "whole tiles");
    for (int cb = 0; cb < kNd; cb += 8) {
      for (int c = cb; c < cb + 8; ++c)
        for (int r = c + 1; r < cb + 8; ++r) t[kNd * r + c] = t[kNd * c + r];
      for (int rb = cb + 8; rb < kNd; rb += 8) {
        const double* src = t + kNd * cb + rb;  // column cb, rows rb ..
        double* dst = t + kNd * rb + cb;        // column rb, rows cb ..
        for (int c = 0; c < 8; ++c)
          for (int r = 0; r < 8; ++r) dst[kNd * r + c] = src[kNd * c + r];
      }
    }
  }
  if (constrained) {
    acc.finish(constraints, out);
    // The constraint Hessians are summed as full matrices: mirror the lower triangle so
    // the tangent stays exactly symmetric (solvers that read one triangle see the same).
    if (want_tangent) out.tangent.triangularView<Eigen::StrictlyUpper>() = out.tangent.transpose();
  }
}

void ElementRule::validate() const {
  auto check = [](const char* name, int n) {
    if (n < 1 || n > 32) {
      std::ostringstream os;
      os << "element rule " << name << ": expected 1..32 Gauss points, found " << n;
      throw InputError(os.str());
    }
  };
  check("n_inplane", n_inplane);
  check("n_thickness", n_thickness);
}

void ConstraintTerms::validate() const {
  auto check = [](const char* name, double v, bool non_negative) {
    if (!std::isfinite(v) || (non_negative && v < 0.0)) {
      std::ostringstream os;
      os << "constraint terms " << name << ": expected a finite" << (non_negative ? " non-negative" : "")
         << " value, found " << v;
      throw InputError(os.str());
    }
  };
  check("kappa", kappa, true);
  check("p", p, false);
  check("k_fibre", k_fibre, true);
  check("T", T, false);
}

quadrature::TensorRule<3> ElementRule::brick() const {
  validate();
  return quadrature::gauss_3d(n_inplane, n_inplane, n_thickness);
}

quadrature::TensorRule<2> ElementRule::plane() const {
  validate();
  return quadrature::gauss_2d(n_inplane, n_thickness);
}

ElementResult brick_element(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                            const quadrature::TensorRule<3>& rule, bool want_tangent,
                            const ConstraintTerms& constraints) {
  ElementResult out;
  BrickScratch scratch;
  BrickKernel(rule).evaluate(X_e, x_e, material, want_tangent, constraints, scratch, out);
  return out;
}

ElementResult brick_element_reference(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                                      const quadrature::TensorRule<3>& rule, bool want_tangent,
                                      const ConstraintTerms& constraints) {
  return integrate<basis::BicubicHermiteLinear, 3>(X_e, x_e, material, rule, want_tangent, constraints);
}

ElementResult plane_element(const PlaneParams& X_e, const PlaneParams& x_e, const Material& material,
                            const quadrature::TensorRule<2>& rule, bool want_tangent,
                            const ConstraintTerms& constraints) {
  return integrate<basis::CubicHermiteLinear, 2>(X_e, x_e, material, rule, want_tangent, constraints);
}

std::vector<Mat3> brick_deformation_gradients(const BrickParams& X_e, const BrickParams& x_e,
                                              const quadrature::TensorRule<3>& rule) {
  return gradients<basis::BicubicHermiteLinear, 3>(X_e, x_e, rule);
}

std::vector<Mat3> plane_deformation_gradients(const PlaneParams& X_e, const PlaneParams& x_e,
                                              const quadrature::TensorRule<2>& rule) {
  return gradients<basis::CubicHermiteLinear, 2>(X_e, x_e, rule);
}

std::string to_string(ElementResult::Status status) {
  switch (status) {
    case ElementResult::Status::kOk:
      return "ok";
    case ElementResult::Status::kInvertedReference:
      return "inverted-reference";
    case ElementResult::Status::kInverted:
      return "inverted";
  }
  return "unknown";
}

}  // namespace sf::forming
