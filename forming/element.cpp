#include "forming/element.hpp"

#include <Eigen/LU>
#include <algorithm>
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

template <class Basis, int D>
ElementResult integrate(const Eigen::Matrix<double, Basis::kNumFunctions, D>& X_e,
                        const Eigen::Matrix<double, Basis::kNumFunctions, D>& x_e, const Material& material,
                        const quadrature::TensorRule<D>& rule, bool want_tangent) {
  constexpr int NF = Basis::kNumFunctions;
  constexpr int ND = D * NF;
  ElementResult r;
  r.force = VecX::Zero(ND);
  if (want_tangent) r.tangent = MatX::Zero(ND, ND);
  r.min_det_f = std::numeric_limits<double>::infinity();
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

quadrature::TensorRule<3> ElementRule::brick() const {
  validate();
  return quadrature::gauss_3d(n_inplane, n_inplane, n_thickness);
}

quadrature::TensorRule<2> ElementRule::plane() const {
  validate();
  return quadrature::gauss_2d(n_inplane, n_thickness);
}

ElementResult brick_element(const BrickParams& X_e, const BrickParams& x_e, const Material& material,
                            const quadrature::TensorRule<3>& rule, bool want_tangent) {
  return integrate<basis::BicubicHermiteLinear, 3>(X_e, x_e, material, rule, want_tangent);
}

ElementResult plane_element(const PlaneParams& X_e, const PlaneParams& x_e, const Material& material,
                            const quadrature::TensorRule<2>& rule, bool want_tangent) {
  return integrate<basis::CubicHermiteLinear, 2>(X_e, x_e, material, rule, want_tangent);
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
