#include "forming/stability/spectral.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/quadrature/gauss.hpp"

namespace sf::forming::stability {
namespace {

using Cd = std::complex<double>;
using MatC = Eigen::MatrixXcd;
using VecC = Eigen::VectorXcd;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat39 = Eigen::Matrix<double, 3, 9>;
using Mat93 = Eigen::Matrix<double, 9, 3>;
using RowV9 = Eigen::Matrix<double, 1, 9>;

// Legendre polynomials P_0..P_N and their derivatives at z in [-1, 1].
void legendre(int n_deg, double z, Eigen::VectorXd& p, Eigen::VectorXd& dp) {
  p.resize(n_deg + 1);
  dp.resize(n_deg + 1);
  p(0) = 1.0;
  dp(0) = 0.0;
  if (n_deg == 0) return;
  p(1) = z;
  dp(1) = 1.0;
  for (int m = 1; m < n_deg; ++m) {
    p(m + 1) = ((2.0 * m + 1.0) * z * p(m) - m * p(m - 1)) / (m + 1.0);
    dp(m + 1) = dp(m - 1) + (2.0 * m + 1.0) * p(m);
  }
}

// The discretisation: field component j (0 = s, 1 = t, 2 = z), coefficient m of P_m at
// column j * (N + 1) + m. grad(v) is stored as a 9-vector, entry 3 j + k = d v_j / d x_k.
class Discretisation {
 public:
  Discretisation(int n_deg, double wave_number, double half_thickness)
      : n_(n_deg + 1), k_(wave_number), h_(half_thickness) {}

  int n() const { return n_; }
  int n_coefficients() const { return 3 * n_; }

  // 3 x 3n: the values of the three components at z.
  MatC values(double z) const {
    Eigen::VectorXd p, dp;
    legendre(n_ - 1, z, p, dp);
    MatC v = MatC::Zero(3, 3 * n_);
    for (int j = 0; j < 3; ++j) v.block(j, j * n_, 1, n_) = p.transpose().cast<Cd>();
    return v;
  }
  // 9 x 3n: grad(v) at z; d/ds = i K, d/dt = 0, d/dz = (1 / H) d/dzeta.
  MatC gradient(double z) const {
    Eigen::VectorXd p, dp;
    legendre(n_ - 1, z, p, dp);
    MatC g = MatC::Zero(9, 3 * n_);
    for (int j = 0; j < 3; ++j) {
      g.block(3 * j + 0, j * n_, 1, n_) = Cd(0.0, k_) * p.transpose().cast<Cd>();
      g.block(3 * j + 2, j * n_, 1, n_) = (dp.transpose() / h_).cast<Cd>();
    }
    return g;
  }

 private:
  int n_;
  double k_, h_;
};

// f1 = grad(xi) f - (f.grad(xi).f) f as a 3 x 9 map of grad(xi).
Mat39 fibre_perturbation_map(const Vec3& f) {
  Mat39 m = Mat39::Zero();
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      m(j, 3 * j + k) += f(k);
      for (int l = 0; l < 3; ++l) m(l, 3 * j + k) -= f(l) * f(j) * f(k);
    }
  return m;
}
// f.grad(v).f as a 1 x 9 row.
RowV9 stretch_row(const Vec3& f) {
  RowV9 r;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) r(3 * j + k) = f(j) * f(k);
  return r;
}
// vec(f1 (x) f + f (x) f1) as a 9 x 3 map of f1.
Mat93 fibre_stress_map(const Vec3& f) {
  Mat93 m = Mat93::Zero();
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      m(3 * j + k, j) += f(k);
      m(3 * j + k, k) += f(j);
    }
  return m;
}
// Symmetric part of a 9-vector gradient.
Mat9 symmetriser() {
  Mat9 s = Mat9::Zero();
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      s(3 * j + k, 3 * j + k) += 0.5;
      s(3 * j + k, 3 * k + j) += 0.5;
    }
  return s;
}

struct NullSpace {
  MatC basis;           // orthonormal columns
  MatC pseudo_inverse;  // minimum-norm least-squares solution operator
};
NullSpace null_space(const MatC& c, double tolerance) {
  Eigen::JacobiSVD<MatC> svd(c, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  const double cut = tolerance * (s.size() > 0 ? s(0) : 0.0);
  int rank = 0;
  while (rank < s.size() && s(rank) > cut) ++rank;
  NullSpace ns;
  ns.basis = svd.matrixV().rightCols(c.cols() - rank);
  MatC sinv = MatC::Zero(c.cols(), c.rows());
  for (int i = 0; i < rank; ++i) sinv(i, i) = 1.0 / s(i);
  ns.pseudo_inverse = svd.matrixV() * sinv * svd.matrixU().adjoint();
  return ns;
}

std::vector<Cd> sorted_eigenvalues(const MatC& m) {
  Eigen::ComplexEigenSolver<MatC> es(m, false);
  std::vector<Cd> ev(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
  std::sort(ev.begin(), ev.end(), [](Cd x, Cd y) { return x.real() > y.real(); });
  return ev;
}

}  // namespace

void SpectralOptions::validate() const {
  if (degree < 2 || degree > 29) throw std::invalid_argument("SpectralOptions: degree must be in [2, 29]");
  if (!(rank_tolerance > 0.0) || !(invariance_tolerance > 0.0))
    throw std::invalid_argument("SpectralOptions: tolerances must be positive");
}

std::string SpectralReport::brief() const {
  const char* s = status == Status::kOk ? "ok" : status == Status::kNotNormalMode ? "not a normal mode" : "failed";
  return fmt::format(
      "spectral: {}; G = {:.10g} 1/s; {} state(s), {} velocity dofs; constraint residual {:.1e}, "
      "invariance residual {:.1e}{}{}",
      s, growth_rate, n_state, n_velocity, constraint_residual, invariance_residual, message.empty() ? "" : "; ",
      message);
}

SpectralReport solve_spectral(const SheetState& sheet, double theta, double wave_number,
                              const SpectralOptions& options) {
  options.validate();
  sheet.validate(1e-6);
  if (!(wave_number > 0.0)) throw std::invalid_argument("solve_spectral: the wave number must be > 0");

  const bool fibres = options.with_fibres && !sheet.fibres.empty();
  const double mu = sheet.viscosity;
  const double half = 0.5 * sheet.thickness;
  // Displacements of degree N, velocities of degree N + 1: at a wave direction normal to a
  // family, u_z' = 2 i K D_ts xi_t, one degree above xi.
  const Discretisation dx(options.degree, wave_number, half);
  const Discretisation du(options.degree + 1, wave_number, half);
  const int nx = dx.n(), ncx = dx.n_coefficients();
  const int nu_ = du.n(), ncu = du.n_coefficients();

  // Wave frame: s along n, t along the crests, z normal.
  const Vec2 nv = wave_direction(theta);
  const Vec2 tv = crest_direction(theta);
  Mat3 d0 = Mat3::Zero();
  d0(0, 0) = nv.dot(sheet.rate * nv);
  d0(0, 1) = d0(1, 0) = nv.dot(sheet.rate * tv);
  d0(1, 1) = tv.dot(sheet.rate * tv);
  d0(2, 2) = sheet.rate33();
  Mat2 sigma = 2.0 * mu * (sheet.rate + sheet.rate.trace() * Mat2::Identity());
  if (fibres) sigma += sheet.fibre_stress();
  const double sigma_sn[2] = {nv.dot(sigma * nv), tv.dot(sigma * nv)};  // (sigma0 n) in s, t

  struct FibreW {
    Vec3 f;
    double tension;
  };
  std::vector<FibreW> fw;
  if (fibres)
    for (const Fibre& f : sheet.fibres) fw.push_back({Vec3(f.direction.dot(nv), f.direction.dot(tv), 0.0), f.tension});

  // ---- volume terms by Gauss-Legendre quadrature (exact: integrands of degree <= 2N + 2)
  const quadrature::Rule1D rule = quadrature::gauss_legendre(std::min(32, options.degree + 3));
  const Mat9 sym = symmetriser();
  MatC a = MatC::Zero(ncu, ncu);   // viscous: du^H A u = int 2 mu D(u) : D(du)* dz
  MatC bf = MatC::Zero(ncu, ncx);  // fibre tilt: du^H Bf xi = int sum T_f (f1 f + f f1) : grad(du)* dz
  Eigen::Matrix<double, 9, 9> fibre_op = Eigen::Matrix<double, 9, 9>::Zero();
  for (const FibreW& f : fw) fibre_op += f.tension * fibre_stress_map(f.f) * fibre_perturbation_map(f.f);
  for (std::size_t q = 0; q < rule.points.size(); ++q) {
    const double z = 2.0 * rule.points[q] - 1.0;
    const double w = 2.0 * rule.weights[q] * half;  // dz = H dzeta
    const MatC gu = du.gradient(z);
    const MatC sg = sym.cast<Cd>() * gu;
    a += (2.0 * mu * w) * sg.adjoint() * sg;
    if (fibres) bf += w * gu.adjoint() * fibre_op.cast<Cd>() * dx.gradient(z);
  }

  // ---- surface terms: -du_beta*(H) (sigma0 n)_beta i K xi_z(H) + the same at -H
  const MatC top_u = du.values(1.0), bottom_u = du.values(-1.0);
  const MatC top_x = dx.values(1.0), bottom_x = dx.values(-1.0);
  MatC bs = MatC::Zero(ncu, ncx);
  for (int beta = 0; beta < 2; ++beta) {
    const Cd c = Cd(0.0, -wave_number) * sigma_sn[beta];
    bs += c * (top_u.row(beta).adjoint() * top_x.row(2) - bottom_u.row(beta).adjoint() * bottom_x.row(2));
  }

  // ---- velocity constraints at the Chebyshev-Lobatto points of degree N + 1:
  // div u = 0 and f.grad(u).f + 2 f1.D0.f = 0 for each family
  const int rows = 1 + static_cast<int>(fw.size());
  MatC cu = MatC::Zero(rows * nu_, ncu);  // acting on u
  MatC eu = MatC::Zero(rows * nu_, ncx);  // rhs(xi) = E xi
  for (int i = 0; i < nu_; ++i) {
    const double z = std::cos(kPi * i / (nu_ - 1));
    const MatC gu = du.gradient(z), gx = dx.gradient(z);
    cu.row(rows * i) = gu.row(0) + gu.row(4) + gu.row(8);
    for (std::size_t f = 0; f < fw.size(); ++f) {
      const int r = rows * i + 1 + static_cast<int>(f);
      cu.row(r) = stretch_row(fw[f].f).cast<Cd>() * gu;
      const Eigen::Matrix<double, 1, 9> d0f = -2.0 * (d0 * fw[f].f).transpose() * fibre_perturbation_map(fw[f].f);
      eu.row(r) = d0f.cast<Cd>() * gx;
    }
  }
  const NullSpace nsu = null_space(cu, options.rank_tolerance);
  SpectralReport report;
  report.n_velocity = static_cast<int>(nsu.basis.cols());
  if (report.n_velocity == 0) {
    report.message = "no admissible velocity";
    return report;
  }
  // u = P xi - Z (Z^H A Z)^-1 Z^H (A P + Bf + Bs) xi, P = C^+ E.
  const MatC p = nsu.pseudo_inverse * eu;
  const MatC kz = nsu.basis.adjoint() * a * nsu.basis;
  const Eigen::LLT<MatC> llt(kz);
  if (llt.info() != Eigen::Success) {
    report.message = "the viscous system on the admissible velocities is not positive definite";
    return report;
  }
  const MatC velocity = p - nsu.basis * llt.solve(nsu.basis.adjoint() * (a * p + bf + bs));  // ncu x ncx

  // d(xi)/dt = u + D0 xi in the velocity space (degree N + 1): rate = U + Ext D0.
  MatC rate = velocity;
  for (int j = 0; j < 3; ++j)
    for (int l = 0; l < 3; ++l)
      if (d0(j, l) != 0.0) rate.block(j * nu_, l * nx, nx, nx) += d0(j, l) * MatC::Identity(nx, nx);
  // Ext: degree-N coefficients into the degree-(N + 1) layout.
  MatC ext = MatC::Zero(ncu, ncx);
  for (int j = 0; j < 3; ++j) ext.block(j * nu_, j * nx, nx, nx) = MatC::Identity(nx, nx);

  // The buckle itself, xi = e3 (uniform): admissible in every direction; its instantaneous
  // growth rate is the mean of the z-rate over the thickness (the P_0 coefficient).
  {
    VecC buckle = VecC::Zero(ncx);
    buckle(2 * nx) = 1.0;
    const VecC r = rate * buckle;
    report.buckle_growth_rate = r(2 * nu_).real();
  }

  if (!fibres) {
    // State: surface displacements (top, bottom); xi_z linear in zeta carries them.
    MatC x = MatC::Zero(ncx, 2);
    x(2 * nx + 0, 0) = 0.5;
    x(2 * nx + 1, 0) = 0.5;
    x(2 * nx + 0, 1) = 0.5;
    x(2 * nx + 1, 1) = -0.5;
    MatC surf(2, ncu);
    surf.row(0) = top_u.row(2);
    surf.row(1) = bottom_u.row(2);
    const MatC m = surf * velocity * x + sheet.rate33() * MatC::Identity(2, 2);
    report.n_state = 2;
    Eigen::ComplexEigenSolver<MatC> es(m);
    for (int i = 0; i < 2; ++i) {
      const VecC v = es.eigenvectors().col(i);
      const bool sinuous = std::abs(v(0) + v(1)) > std::abs(v(0) - v(1));
      (sinuous ? report.sinuous : report.varicose) = es.eigenvalues()(i).real();
    }
    report.eigenvalues = sorted_eigenvalues(m);
    report.growth_rate = report.eigenvalues.front().real();
    report.status = SpectralReport::Status::kOk;
    return report;
  }

  // Admissible displacements: div xi = 0 and f.grad(xi).f = 0 for each family.
  MatC cx = MatC::Zero(rows * nx, ncx);
  for (int i = 0; i < nx; ++i) {
    const double z = std::cos(kPi * i / (nx - 1));
    const MatC g = dx.gradient(z);
    cx.row(rows * i) = g.row(0) + g.row(4) + g.row(8);
    for (std::size_t f = 0; f < fw.size(); ++f)
      cx.row(rows * i + 1 + static_cast<int>(f)) = stretch_row(fw[f].f).cast<Cd>() * g;
  }
  const MatC zx = null_space(cx, options.rank_tolerance).basis;
  report.n_state = static_cast<int>(zx.cols());
  if (report.n_state == 0) {
    report.message = "no admissible displacement";
    return report;
  }
  // Consistency of the velocity constraints for admissible xi (relative to the size of the
  // constraint operator: rhs(xi) itself vanishes in the generic case).
  const MatC rhs = eu * zx;
  const double rhs_scale = eu.norm();
  report.constraint_residual = rhs_scale > 0.0 ? (cu * p * zx - rhs).norm() / rhs_scale : 0.0;
  if (report.constraint_residual > options.invariance_tolerance) {
    report.message = "the velocity constraints are inconsistent for admissible displacements";
    return report;
  }
  const MatC ez = ext * zx;  // orthonormal columns
  const MatC rz = rate * zx;
  const MatC m = ez.adjoint() * rz;
  const double rate_norm = rz.norm();
  report.invariance_residual = rate_norm > 0.0 ? (rz - ez * m).norm() / rate_norm : 0.0;
  if (report.invariance_residual > options.invariance_tolerance) {
    report.status = SpectralReport::Status::kNotNormalMode;
    report.growth_rate = report.buckle_growth_rate;
    report.message =
        "the flow carries admissible displacements out of the admissible space (a wave direction "
        "normal to a fibre family: the buckle excites shear along the crests); growth_rate is the "
        "buckle's instantaneous rate";
    return report;
  }
  report.eigenvalues = sorted_eigenvalues(m);
  report.growth_rate = report.eigenvalues.front().real();
  report.status = SpectralReport::Status::kOk;
  return report;
}

}  // namespace sf::forming::stability
