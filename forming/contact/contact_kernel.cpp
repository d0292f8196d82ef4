#include "forming/contact/contact_kernel.hpp"

#include <algorithm>
#include <cmath>

#include "common/core/error.hpp"
#include "common/linalg/dense_kernels.hpp"

namespace sf::forming {
namespace {

// Adds scale * phi_a * v_i into entry (a, i) of a local vector.
void add_jt(const PointKinematics& k, double scale, const Vec3& v, VecX& out) {
  for (int a = 0; a < k.n; ++a) out.segment<3>(3 * a) += (scale * k.phi[static_cast<std::size_t>(a)]) * v;
}

constexpr int kMaxLocal = 3 * kMaxPointFunctions;
constexpr int kMaxRank = 7;
// A point's stiffness factors (U, V: 3n x 7) and rows over the local dofs, on the stack.
using Factors = Eigen::Matrix<double, Eigen::Dynamic, kMaxRank, Eigen::ColMajor, kMaxLocal, kMaxRank>;
// K += U V^T (m x m, U and V m x rank, all column-major, leading dimension m) by the
// run-time chosen kernel of common/linalg/dense_kernels.hpp: its lower triangle from
// U V^T and its upper from the lower triangle of V U^T. (Eigen's own product would
// start OpenMP threads for these sizes, whose spinning cost more than the product.)
void add_uvt(int m, int rank, const double* u, const double* v, MatX& K, MatX& lower, MatX& upper) {
  lower.setZero(m, m);
  upper.setZero(m, m);
  linalg::add_atb_lower(m, rank, u, m, v, m, lower.data(), m);
  linalg::add_atb_lower(m, rank, v, m, u, m, upper.data(), m);
  for (int j = 0; j < m; ++j) {
    K(j, j) += lower(j, j);
    for (int i = j + 1; i < m; ++i) {
      K(i, j) += lower(i, j);
      K(j, i) += upper(i, j);
    }
  }
}

template <int R>
using LocalRows = Eigen::Matrix<double, R, Eigen::Dynamic, R == 1 ? Eigen::RowMajor : Eigen::ColMajor, R, kMaxLocal>;

}  // namespace

PointState add_contact_point(const PointKinematics& k, const PointLaw& law, const PointRates& rates, double weight,
                             LocalContribution& out) {
  SF_ASSERT(k.n > 0 && k.n <= kMaxPointFunctions, "contact point: 1..32 local functions");
  SF_ASSERT(out.force.size() == 3 * k.n, "contact point: local force of 3 n entries");
  const int m = 3 * k.n;
  const double w = weight;
  const double p = law.normal.pressure;
  const double S = law.normal.stiffness;
  const Vec3& n = k.normal;
  const bool tangent = out.stiffness.size() > 0;
  PointState state;
  state.pressure = p;

  // ---- normal
  out.energy += w * law.normal.energy;
  if (p != 0.0) add_jt(k, -w * p, n, out.force);
  // Stiffness factors K = U V^T (contact_kernel.hpp): U = [Phi N_h R], V accumulated.
  const int rank = k.tool ? 3 : kMaxRank;
  Factors U, V;
  bool stiff = false;
  if (tangent) {
    U.setZero(m, kMaxRank);
    V.setZero(m, kMaxRank);
    for (int a = 0; a < k.n; ++a) {
      const auto ia = static_cast<std::size_t>(a);
      U.block<3, 3>(3 * a, 0).diagonal().setConstant(k.phi[ia]);
      if (!k.tool) U.block<3, 2>(3 * a, 3) = n * (k.H_inv * Vec2(k.rho1[ia], k.rho2[ia])).transpose();
    }
  }
  if (tangent && (S != 0.0 || p != 0.0)) {
    stiff = true;
    if (k.tool) {
      // w phi_a phi_c (S n (dg/dx)^T - p dn/dx) = Phi B Phi^T: V_Phi = Phi B^T.
      const Mat3 Bt = (w * (S * n * k.gap_gradient.transpose() - p * k.dn_dx)).transpose();
      for (int c = 0; c < k.n; ++c) V.block<3, 3>(3 * c, 0) += k.phi[static_cast<std::size_t>(c)] * Bt;
    } else {
      // w (S dg dg^T - p d2g), -d2g_ac = phi_a phi_c T C T^T + phi_c n q_a^T + phi_a q_c n^T
      // + g (rho_a . H^-1 rho_c) n n^T, q_a = T H^-1 rho_a (header):
      //   Phi [A Phi^T + w p T N_h^T] + N_h [w p (Phi T + g N_r)]^T,
      //   A = w (S n n^T + p T C T^T), N_r = rho_c,l n_j.
      const Mat3 nn = n * n.transpose();
      const Mat2 C = k.M_inv * k.kappa * k.H_inv;
      const Mat3 At = (w * (S * nn + p * (k.T * C * k.T.transpose()))).transpose();
      const double wp = w * p;
      for (int c = 0; c < k.n; ++c) {
        const auto ic = static_cast<std::size_t>(c);
        const Vec2 rc(k.rho1[ic], k.rho2[ic]);
        const Vec3 qc = k.T * (k.H_inv * rc);
        V.block<3, 3>(3 * c, 0) += k.phi[ic] * At + wp * n * qc.transpose();
        V.block<3, 2>(3 * c, 3) += wp * (k.phi[ic] * k.T + k.gap * n * rc.transpose());
      }
    }
  }
  const auto finish = [&]() {
    if (!stiff) return;
    if (out.deferred) {
      if (out.rank + rank > out.u.cols()) {
        const Index cols = std::max<Index>(2 * out.u.cols(), out.rank + rank);
        out.u.conservativeResize(m, cols);
        out.v.conservativeResize(m, cols);
      }
      out.u.middleCols(out.rank, rank) = U.leftCols(rank);
      out.v.middleCols(out.rank, rank) = V.leftCols(rank);
      out.rank += rank;
    } else {
      add_uvt(m, rank, U.data(), V.data(), out.stiffness, out.lower, out.upper);
    }
  };

  // ---- friction
  if (!law.friction() || !rates.have) {
    finish();
    return state;
  }
  const Mat3 P = Mat3::Identity() - n * n.transpose();
  const Vec3 vt = P * rates.relative;
  const double eps = law.stick_velocity;
  // Coulomb: the bearing pressure (the rounded penalty's, never a tail's tie: contact_law.hpp).
  const double mu_p = law.coulomb * law.normal.bearing;
  // The slip-distance form (PointLaw::distance): Coulomb's own relative rate (shifted by the
  // elastic slip) and the exact return map's s = max(|v_T,c|, eps), sticking below eps.
  const bool distance = law.distance && law.coulomb > 0.0;
  SF_ASSERT(!(distance && out.damping.size() > 0), "contact point: the slip-distance Coulomb form is quasi-static");
  const Vec3 wc = rates.relative + rates.coulomb_shift;
  const Vec3 vtc = distance ? Vec3(P * wc) : vt;
  const double s = distance ? std::max(vtc.norm(), eps) : std::sqrt(vt.squaredNorm() + eps * eps);
  const bool sliding = !distance || vtc.norm() > eps;  // ds/dv_T,c = v_T,c / s, else 0 (stick)
  const double c_c = law.coulomb > 0.0 ? mu_p / s : 0.0;
  const double c = law.viscous + c_c;
  state.slip_rate = vt;
  state.coulomb_slip_rate = vtc;
  if (distance) {
    state.shear = -law.viscous * vt - c_c * vtc;
    if (law.viscous != 0.0) add_jt(k, w * law.viscous, vt, out.force);
    if (c_c != 0.0) add_jt(k, w * c_c, vtc, out.force);
  } else {
    state.shear = -c * vt;
    if (c != 0.0) add_jt(k, w * c, vt, out.force);
  }
  if (!tangent && out.damping.size() == 0) {
    finish();
    return state;
  }

  // J^T v_T, a local vector.
  VecX jt_vt = VecX::Zero(m);
  add_jt(k, 1.0, vt, jt_vt);
  if (out.damping.size() > 0) {
    // w [ (J^T v_T) dc/dv + c J^T P J ], dc/dv = -(mu p / s^3) v_T^T J.
    for (int cc = 0; cc < k.n; ++cc) {
      const double phic = k.phi[static_cast<std::size_t>(cc)];
      for (int a = 0; a < k.n; ++a)
        out.damping.block<3, 3>(3 * a, 3 * cc) += (w * c * k.phi[static_cast<std::size_t>(a)] * phic) * P;
      if (law.coulomb > 0.0) {
        const Vec3 dcdv = (-mu_p / (s * s * s) * phic) * vt;
        out.damping.middleCols<3>(3 * cc) += w * jt_vt * dcdv.transpose();
      }
    }
  }
  if (!tangent) return state;

  // d zeta / du (2 x m, body only) and d n / du (3 x m).
  LocalRows<2> dzeta = LocalRows<2>::Zero(2, m);
  LocalRows<3> dn(3, m);
  if (k.tool) {
    for (int cc = 0; cc < k.n; ++cc) dn.middleCols<3>(3 * cc) = k.phi[static_cast<std::size_t>(cc)] * k.dn_dx;
  } else {
    const Mat32 A = k.T * k.M_inv;
    for (int cc = 0; cc < k.n; ++cc) {
      const auto ic = static_cast<std::size_t>(cc);
      const Vec2 rc(k.rho1[ic], k.rho2[ic]);
      for (int j = 0; j < 3; ++j) {
        const Vec2 dz = k.H_inv * (k.phi[ic] * k.T.row(j).transpose() + (k.gap * n[j]) * rc);
        dzeta(0, 3 * cc + j) = dz[0];  // element-wise: GCC 12 warns on a 2-vector column store
        dzeta(1, 3 * cc + j) = dz[1];
        dn.col(3 * cc + j) = -A * (n[j] * rc + k.kappa * dz);
      }
    }
  }
  // d v_rel / du.
  LocalRows<3> dw = LocalRows<3>::Zero(3, m);
  if (rates.inv_dt > 0.0)
    for (int cc = 0; cc < k.n; ++cc)
      dw.middleCols<3>(3 * cc).diagonal().setConstant(k.phi[static_cast<std::size_t>(cc)] * rates.inv_dt);
  if (!k.tool) dw -= rates.master_d1 * dzeta.row(0) + rates.master_d2 * dzeta.row(1);
  const LocalRows<3> dvt = -n.dot(rates.relative) * dn - n * (rates.relative.transpose() * dn) + P * dw;
  LocalRows<1> dg(1, m);  // dg/du
  if (law.coulomb > 0.0 || law.viscous_slope != 0.0)
    for (int cc = 0; cc < k.n; ++cc)
      dg.segment<3>(3 * cc) = k.phi[static_cast<std::size_t>(cc)] * k.gap_gradient.transpose();
  // Friction stiffness w [ (J^T v_T) dc/du + c J^T dv_T/du + c (dJ^T/du) v_T ], viscous on
  // v_T and Coulomb on v_T,c (the velocity form: v_T,c = v_T, always sliding; the
  // slip-distance form: P (v_rel + shift), the shift state, so constant):
  //   Phi [w (c_v dv_T + v_T c_v' dg + c_c dv_T,c + v_T,c dc_c)] - R [w dzeta],
  //   R = rho_a,l (c_v v_T + c_c v_T,c)_i   (body only),
  //   dc_c = -(mu S_b / s) dg - [sliding] (mu p / s^3) v_T,c^T dv_T,c,  dp/du = -S dg/du.
  LocalRows<3> dvtc_distance;
  if (distance) dvtc_distance = -n.dot(wc) * dn - n * (wc.transpose() * dn) + P * dw;
  const LocalRows<3>& dvtc = distance ? dvtc_distance : dvt;
  LocalRows<3> phi_part = law.viscous * dvt + c_c * dvtc;
  if (law.coulomb > 0.0) {
    LocalRows<1> dc = (-law.coulomb * law.normal.bearing_stiffness / s) * dg;
    if (sliding) dc -= (mu_p / (s * s * s)) * (vtc.transpose() * dvtc);
    phi_part.noalias() += vtc * dc;
  }
  if (law.viscous_slope != 0.0) phi_part.noalias() += vt * (law.viscous_slope * dg);
  V.leftCols<3>() += w * phi_part.transpose();
  if (!k.tool) {
    const Vec3 r = law.viscous * vt + c_c * vtc;
    for (int a = 0; a < k.n; ++a) {
      const auto ia = static_cast<std::size_t>(a);
      U.block<3, 2>(3 * a, 5) = r * Vec2(k.rho1[ia], k.rho2[ia]).transpose();
    }
    V.middleCols<2>(5) -= w * dzeta.transpose();
  }
  stiff = true;
  finish();
  return state;
}

}  // namespace sf::forming

namespace sf::forming {

void LocalContribution::defer_stiffness(int points) {
  deferred = true;
  rank = 0;
  const Index m = stiffness.rows();
  const Index cols = static_cast<Index>(points) * kMaxRank;
  if (u.rows() != m || u.cols() < cols) {
    u.resize(m, cols);
    v.resize(m, cols);
  }
}

void LocalContribution::finish_stiffness() {
  if (rank > 0) add_uvt(static_cast<int>(stiffness.rows()), rank, u.data(), v.data(), stiffness, lower, upper);
  rank = 0;
}

}  // namespace sf::forming
