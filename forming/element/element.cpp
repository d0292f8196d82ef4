#include "forming/element/element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
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

// Geometry and deformation at one point: G = dX/dxi, g^T = G^-T (dN/dxi)^T (3 x 32,
// gt[32 A + k] = dN_k/dX_A) and F (row-major, F[3 i + A]). X and x are the element
// parameters column-major (32 x 3: x[32 i + k]). Returns det G (the rest is unset when
// it is not positive).
template <int W>
[[gnu::always_inline]] inline double point_kinematics(const double* dxi, const double* X, const double* x, double* gt,
                                                      double* F) {
  using V = linalg::simd::Vec<W>;
  using linalg::simd::at;
  double G[3][3];
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) {
      V s = V{};
      for (int k = 0; k < kNf; k += W) s += at<W>(X + kNf * i + k) * at<W>(dxi + kNf * a + k);
      G[i][a] = linalg::simd::sum<W>(s);
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
  for (int i = 0; i < 3; ++i)
    for (int A = 0; A < 3; ++A) {
      V s = V{};
      for (int k = 0; k < kNf; k += W) s += at<W>(x + kNf * i + k) * at<W>(gt + kNf * A + k);
      F[3 * i + A] = linalg::simd::sum<W>(s);
    }
  return det;
}

// Force (coordinate-major, f[32 i + k] += dV sum_A P_iA dN_k/dX_A, P = F S) and, with
// `tangent`, the point's rows of the two products: b (6 x 96, B in Voigt rows), d (6 x 96,
// dV CC B), ga (3 x 32, dN/dX) and gb (3 x 32, dV S dN/dX). F, S, P row-major; CC
// row-major 6 x 6.
template <int W>
[[gnu::always_inline]] inline void point_rows(const double* gt, const double* F, const double* S, const double* CC,
                                              double dv, bool tangent, double* f, double* b, double* d, double* ga,
                                              double* gb) {
  using V = linalg::simd::Vec<W>;
  using linalg::simd::at;
  double P[9];
  for (int i = 0; i < 3; ++i)
    for (int A = 0; A < 3; ++A)
      P[3 * i + A] = dv * (F[3 * i] * S[A] + F[3 * i + 1] * S[3 + A] + F[3 * i + 2] * S[6 + A]);
  for (int k = 0; k < kNf; k += W) {
    const V g0 = at<W>(gt + k), g1 = at<W>(gt + kNf + k), g2 = at<W>(gt + 2 * kNf + k);
    for (int i = 0; i < 3; ++i) at<W>(f + kNf * i + k) += g0 * P[3 * i] + g1 * P[3 * i + 1] + g2 * P[3 * i + 2];
  }
  if (!tangent) return;
  double c[36];
  for (int I = 0; I < 36; ++I) c[I] = dv * CC[I];
  for (int i = 0; i < 3; ++i) {
    const double f0 = F[3 * i], f1 = F[3 * i + 1], f2 = F[3 * i + 2];
    for (int k = 0; k < kNf; k += W) {
      const V g0 = at<W>(gt + k), g1 = at<W>(gt + kNf + k), g2 = at<W>(gt + 2 * kNf + k);
      V bv[6];
      bv[0] = g0 * f0;
      bv[1] = g1 * f1;
      bv[2] = g2 * f2;
      bv[3] = g1 * f0 + g0 * f1;
      bv[4] = g2 * f1 + g1 * f2;
      bv[5] = g2 * f0 + g0 * f2;
      const int col = kNf * i + k;
      for (int I = 0; I < 6; ++I) {
        at<W>(b + kNd * I + col) = bv[I];
        V s = bv[0] * c[6 * I];
        for (int J = 1; J < 6; ++J) s += bv[J] * c[6 * I + J];
        at<W>(d + kNd * I + col) = s;
      }
    }
  }
  for (int k = 0; k < kNf; k += W) {
    const V g0 = at<W>(gt + k), g1 = at<W>(gt + kNf + k), g2 = at<W>(gt + 2 * kNf + k);
    for (int A = 0; A < 3; ++A) {
      at<W>(ga + kNf * A + k) = A == 0 ? g0 : (A == 1 ? g1 : g2);
      at<W>(gb + kNf * A + k) = (g0 * S[3 * A] + g1 * S[3 * A + 1] + g2 * S[3 * A + 2]) * dv;
    }
  }
}

#define SF_BRICK_KERNEL_VARIANTS(attr, suffix, W)                                                                     \
  attr double point_kinematics_##suffix(const double* dxi, const double* X, const double* x, double* gt, double* F) { \
    return point_kinematics<W>(dxi, X, x, gt, F);                                                                     \
  }                                                                                                                   \
  attr void point_rows_##suffix(const double* gt, const double* F, const double* S, const double* CC, double dv,      \
                                bool tangent, double* f, double* b, double* d, double* ga, double* gb) {              \
    point_rows<W>(gt, F, S, CC, dv, tangent, f, b, d, ga, gb);                                                        \
  }
SF_BRICK_KERNEL_VARIANTS(SF_SIMD_AVX512, avx512, 8)
SF_BRICK_KERNEL_VARIANTS(SF_SIMD_AVX2, avx2, 4)
SF_BRICK_KERNEL_VARIANTS(, generic, 2)
#undef SF_BRICK_KERNEL_VARIANTS

using KinematicsFn = double (*)(const double*, const double*, const double*, double*, double*);
using RowsFn = void (*)(const double*, const double*, const double*, const double*, double, bool, double*, double*,
                        double*, double*, double*);

void pick_variants(KinematicsFn& kin, RowsFn& rows) {
  switch (linalg::kernel_isa()) {
    case linalg::KernelIsa::kAvx512:
      kin = point_kinematics_avx512;
      rows = point_rows_avx512;
      return;
    case linalg::KernelIsa::kAvx2:
      kin = point_kinematics_avx2;
      rows = point_rows_avx2;
      return;
    case linalg::KernelIsa::kGeneric:
      break;
  }
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
}

double BrickKernel::force_flops() const {
  // G and F (18 dot products of 32), dN/dX (9 axpy of 32), P (54), force (9 axpy of 32).
  return n_points() * (18.0 * 2 * kNf + 9.0 * 2 * kNf + 54.0 + 9.0 * 2 * kNf);
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
  KinematicsFn kinematics = nullptr;
  RowsFn rows = nullptr;
  pick_variants(kinematics, rows);

  auto resize = [](std::vector<double>& v, std::size_t n) {
    if (v.size() != n) v.assign(n, 0.0);
  };
  const std::size_t nq6 = static_cast<std::size_t>(6 * nq), nq3 = static_cast<std::size_t>(3 * nq);
  if (want_tangent) {
    resize(scratch.b, nq6 * kNd);
    resize(scratch.d, nq6 * kNd);
    resize(scratch.ga, nq3 * kNf);
    resize(scratch.gb, nq3 * kNf);
  }
  // Coordinate-major force first (f_perm), copied to the header's order at the end.
  double f_perm[kNd] = {};
  double gt[3 * kNf];
  const bool constrained = constraints.active();
  ConstraintAccumulator<kNf, 3> acc(constraints, a0, want_tangent && constrained);
  Eigen::Matrix<double, kNf, 3> dn_dX;
  for (int q = 0; q < nq; ++q) {
    double F[9];
    const double det_g = kinematics(&dxi_[static_cast<std::size_t>(3 * kNf * q)], X_e.data(), x_e.data(), gt, F);
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
    const std::size_t q6 = static_cast<std::size_t>(6 * q) * kNd, q3 = static_cast<std::size_t>(3 * q) * kNf;
    rows(gt, F, S, CC, dv, want_tangent, f_perm, want_tangent ? &scratch.b[q6] : nullptr,
         want_tangent ? &scratch.d[q6] : nullptr, want_tangent ? &scratch.ga[q3] : nullptr,
         want_tangent ? &scratch.gb[q3] : nullptr);
    if (constrained) {
      for (int A = 0; A < 3; ++A)
        for (int k = 0; k < kNf; ++k) dn_dX(k, A) = gt[kNf * A + k];
      acc.add_point(Fm, det_f, dn_dX, dv);
    }
  }
  if (out.force.size() != kNd) out.force.resize(kNd);
  for (int k = 0; k < kNf; ++k)
    for (int i = 0; i < 3; ++i) out.force(3 * k + i) = f_perm[kNf * i + k];
  if (want_tangent) {
    scratch.k_mat.assign(static_cast<std::size_t>(kNd * kNd), 0.0);
    scratch.k_geo.assign(static_cast<std::size_t>(kNf * kNf), 0.0);
    linalg::add_atb_lower(kNd, 6 * nq, scratch.b.data(), kNd, scratch.d.data(), kNd, scratch.k_mat.data(), kNd);
    linalg::add_atb_lower(kNf, 3 * nq, scratch.ga.data(), kNf, scratch.gb.data(), kNf, scratch.k_geo.data(), kNf);
    if (out.tangent.rows() != kNd || out.tangent.cols() != kNd) out.tangent.resize(kNd, kNd);
    const double* km = scratch.k_mat.data();
    const double* kg = scratch.k_geo.data();
    double* t = out.tangent.data();
    // Lower triangle of the permuted matrix (row r = 32 i + k >= column c = 32 j + l)
    // to both triangles in the order 3 k + i.
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < kNf; ++l) {
        const int c = kNf * j + l, C = 3 * l + j;
        for (int r = c; r < kNd; ++r) {
          const int i = r / kNf, k = r % kNf, R = 3 * k + i;
          double v = km[kNd * c + r];
          if (i == j) v += kg[kNf * l + k];
          t[kNd * C + R] = v;
          t[kNd * R + C] = v;
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
