#include "forming/contact/contact_kernel.hpp"

#include <cmath>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

// Adds scale * phi_a * v_i into entry (a, i) of a local vector.
void add_jt(const PointKinematics& k, double scale, const Vec3& v, VecX& out) {
  for (int a = 0; a < k.n; ++a) out.segment<3>(3 * a) += (scale * k.phi[static_cast<std::size_t>(a)]) * v;
}

// The normal stiffness of a body contact: w (S dg dg^T - p d2g), by 3 x 3 blocks.
void body_normal_stiffness(const PointKinematics& k, double w, double S, double p, MatX& K) {
  const Vec3& n = k.normal;
  const Mat3 nn = n * n.transpose();
  const Mat2 C = k.M_inv * k.kappa * k.H_inv;
  const Mat3 Q1 = k.T * C * k.T.transpose();
  std::array<Vec3, kMaxPointFunctions> q;
  std::array<Vec2, kMaxPointFunctions> hr;  // H^-1 rho_a
  for (int a = 0; a < k.n; ++a) {
    const auto ia = static_cast<std::size_t>(a);
    hr[ia] = k.H_inv * Vec2(k.rho1[ia], k.rho2[ia]);
    q[ia] = k.T * hr[ia];
  }
  for (int c = 0; c < k.n; ++c) {
    const auto ic = static_cast<std::size_t>(c);
    const Vec2 rc(k.rho1[ic], k.rho2[ic]);
    for (int a = 0; a < k.n; ++a) {
      const auto ia = static_cast<std::size_t>(a);
      const double pp = k.phi[ia] * k.phi[ic];
      // -d2g_ac = pp Q1 + phi_c n q_a^T + phi_a q_c n^T + g (rho_a . H^-1 rho_c) n n^T
      Mat3 minus_d2g = pp * Q1 + k.phi[ic] * n * q[ia].transpose() + k.phi[ia] * q[ic] * n.transpose() +
                       (k.gap * hr[ia].dot(rc)) * nn;
      K.block<3, 3>(3 * a, 3 * c) += w * (S * pp * nn + p * minus_d2g);
    }
  }
}

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
  if (tangent && (S != 0.0 || p != 0.0)) {
    if (k.tool) {
      const Mat3 block = S * n * k.gap_gradient.transpose() - p * k.dn_dx;
      for (int c = 0; c < k.n; ++c)
        for (int a = 0; a < k.n; ++a)
          out.stiffness.block<3, 3>(3 * a, 3 * c) +=
              (w * k.phi[static_cast<std::size_t>(a)] * k.phi[static_cast<std::size_t>(c)]) * block;
    } else {
      body_normal_stiffness(k, w, S, p, out.stiffness);
    }
  }

  // ---- friction
  if (!law.friction() || !rates.have) return state;
  const Mat3 P = Mat3::Identity() - n * n.transpose();
  const Vec3 vt = P * rates.relative;
  const double eps = law.stick_velocity;
  const double s = std::sqrt(vt.squaredNorm() + eps * eps);
  const double mu_p = law.coulomb * p;
  const double c = law.viscous + (law.coulomb > 0.0 ? mu_p / s : 0.0);
  state.slip_rate = vt;
  state.shear = -c * vt;
  if (c != 0.0) add_jt(k, w * c, vt, out.force);
  if (!tangent && out.damping.size() == 0) return state;

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
  MatX dzeta = MatX::Zero(2, m);
  MatX dn(3, m);
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
  MatX dw = MatX::Zero(3, m);
  if (rates.inv_dt > 0.0)
    for (int cc = 0; cc < k.n; ++cc)
      dw.middleCols<3>(3 * cc) += (k.phi[static_cast<std::size_t>(cc)] * rates.inv_dt) * Mat3::Identity();
  if (!k.tool) dw -= rates.master_d1 * dzeta.row(0) + rates.master_d2 * dzeta.row(1);
  const MatX dvt = -n.dot(rates.relative) * dn - n * (rates.relative.transpose() * dn) + P * dw;
  // (J^T v_T) dc/du.
  if (law.coulomb > 0.0 || law.viscous_slope != 0.0) {
    Eigen::RowVectorXd dg(m);  // dg/du
    for (int cc = 0; cc < k.n; ++cc)
      dg.segment<3>(3 * cc) = k.phi[static_cast<std::size_t>(cc)] * k.gap_gradient.transpose();
    // dc/du = c_v' dg/du + (mu / s) dp/du - (mu p / s^3) v_T^T dv_T/du, dp/du = -S dg/du.
    Eigen::RowVectorXd dc = law.viscous_slope * dg;
    if (law.coulomb > 0.0) dc += (-law.coulomb * S / s) * dg - (mu_p / (s * s * s)) * (vt.transpose() * dvt);
    out.stiffness.noalias() += w * jt_vt * dc;
  }
  // c (dJ^T/du) v_T (body: the master functions move with zeta) and c J^T dv_T/du.
  for (int a = 0; a < k.n; ++a) {
    const auto ia = static_cast<std::size_t>(a);
    for (int i = 0; i < 3; ++i) {
      auto row = out.stiffness.row(3 * a + i);
      row += (w * c * k.phi[ia]) * dvt.row(i);
      if (!k.tool && (k.rho1[ia] != 0.0 || k.rho2[ia] != 0.0))
        row -= (w * c * vt[i]) * (k.rho1[ia] * dzeta.row(0) + k.rho2[ia] * dzeta.row(1));
    }
  }
  return state;
}

}  // namespace sf::forming
