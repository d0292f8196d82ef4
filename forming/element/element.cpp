#include "forming/element/element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"

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
  MatX hess_j;                                                     // ND x ND
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
              for (int i = 0; i < D; ++i)
                hess_j(D * k + i, D * l + j) += w * (n(k, i) * n(l, j) - n(k, j) * n(l, i));
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
                        const quadrature::TensorRule<D>& rule, bool want_tangent,
                        const ConstraintTerms& constraints) {
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

}  // namespace

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
