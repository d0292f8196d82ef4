#include "forming/material/transversely_isotropic.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "common/core/error.hpp"
#include "forming/material/law_support.hpp"

namespace sf::forming {
namespace {

using detail::add_volumetric;
using detail::bad_parameter;
using detail::fmt;
using detail::inverted_response;
using detail::kVoigtPair;
using detail::outer;
using detail::require_finite;
using detail::require_positive;
using detail::young_isotropic;

// D5 = d2 I5 / dC dC: (a_i a_k d_jl + a_i a_l d_jk + a_j a_k d_il + a_j a_l d_ik) / 2.
Mat6 d2_i5(const Vec3& a) {
  const auto d = [](int p, int q) { return p == q ? 1.0 : 0.0; };
  Mat6 m;
  for (int I = 0; I < 6; ++I) {
    const int i = kVoigtPair[I][0], j = kVoigtPair[I][1];
    for (int K = 0; K < 6; ++K) {
      const int k = kVoigtPair[K][0], l = kVoigtPair[K][1];
      m(I, K) = 0.5 * (a[i] * a[k] * d(j, l) + a[i] * a[l] * d(j, k) + a[j] * a[k] * d(i, l) + a[j] * a[l] * d(i, k));
    }
  }
  return m;
}

const char* const kTi = "transversely isotropic";
const char* const kTiEng = "transversely isotropic engineering constant";

}  // namespace

void TransverselyIsotropicParams::validate() const {
  require_positive(kTi, "mu_T", mu_T);
  require_positive(kTi, "mu_L", mu_L);
  require_finite(kTi, "kappa_f", kappa_f);
  if (!(kappa_f >= 0.0)) bad_parameter(kTi, "kappa_f", "a value >= 0 (MPa)", kappa_f);
  if (!incompressible) {
    require_finite(kTi, "lambda", lambda);
    if (!(lambda + 2.0 * mu_T / 3.0 > 0.0))
      bad_parameter(kTi, "lambda", "lambda > -2 mu_T/3 (positive matrix bulk modulus)", lambda);
  }
  // With mu_T, mu_L and the bulk modulus positive, the small-strain stiffness is
  // positive definite exactly when E_L > 0 (Sherman-Morrison on the fibre term).
  const double e_l = small_strain_moduli(*this).E_L;
  if (!(e_l > 0.0))
    bad_parameter(
        kTi, "kappa_f",
        "a value giving a positive fibre modulus E_L (found E_L = " + fmt(e_l) + " MPa; mu_L is far below mu_T)",
        kappa_f);
}

TransverselyIsotropicModuli small_strain_moduli(const TransverselyIsotropicParams& p) {
  TransverselyIsotropicModuli m;
  const double mu = p.mu_T;
  const double d = 2.0 * p.kappa_f + 4.0 * (p.mu_L - p.mu_T);
  m.G_L = p.mu_L;
  m.G_T = mu;
  if (p.incompressible) {
    m.E_L = 3.0 * mu + d;
    m.E_T = 4.0 * mu * m.E_L / (m.E_L + mu);
    m.nu_LT = 0.5;
  } else {
    const double lam = p.lambda;
    const double a = lam + 2.0 * mu + d;
    m.E_L = young_isotropic(mu, lam) + d;
    m.E_T = 4.0 * mu * (a * (lam + mu) - lam * lam) / (a * (lam + 2.0 * mu) - lam * lam);
    m.nu_LT = lam / (2.0 * (lam + mu));
  }
  m.nu_TT = m.E_T / (2.0 * mu) - 1.0;
  return m;
}

void TransverselyIsotropicEngineering::validate() const {
  require_positive(kTiEng, "E_f", E_f);
  require_positive(kTiEng, "E_T", E_T);
  require_positive(kTiEng, "G_L", G_L);
  if (incompressible) {
    require_finite(kTiEng, "G_T", G_T);
    if (G_T != 0.0)
      bad_parameter(kTiEng, "G_T", "0 for the incompressible law (G_T follows: E_f E_T / (4 E_f - E_T))", G_T);
  } else {
    require_positive(kTiEng, "G_T", G_T);
  }
}

TransverselyIsotropicParams TransverselyIsotropicEngineering::to_params() const {
  validate();
  TransverselyIsotropicParams p;
  p.incompressible = incompressible;
  p.mu_L = G_L;
  if (incompressible) {
    if (!(E_T < 4.0 * E_f)) bad_parameter(kTiEng, "E_T", "E_T < 4 E_f for the incompressible law", E_T);
    p.mu_T = E_f * E_T / (4.0 * E_f - E_T);
    p.kappa_f = 0.5 * (E_f + p.mu_T - 4.0 * G_L);
    if (!(p.kappa_f >= 0.0)) bad_parameter(kTiEng, "G_L", "G_L <= (E_f + G_T)/4 with G_T = " + fmt(p.mu_T), G_L);
  } else {
    const double mu = G_T;
    const double nu = E_T / (2.0 * G_T) - 1.0;  // transverse Poisson ratio nu_TT
    if (!(nu < 1.0))
      bad_parameter(kTiEng, "G_T",
                    "G_T > E_T / 4 (transverse Poisson ratio E_T/(2 G_T) - 1 below 1; use the "
                    "incompressible law for the limit)",
                    G_T);
    // Quadratic qa lambda^2 + qb lambda + qc = 0 (header), solved stably.
    const double qa = E_f * (1.0 - nu) - mu * (1.0 + nu);
    const double qb = E_f * mu * (1.0 - 3.0 * nu);
    const double qc = -2.0 * E_f * nu * mu * mu;
    const double disc = qb * qb - 4.0 * qa * qc;
    bool found = false;
    if (disc >= 0.0) {
      const double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
      const double nan = std::numeric_limits<double>::quiet_NaN();
      const double roots[2] = {qa != 0.0 ? q / qa : nan, q != 0.0 ? qc / q : 0.0};
      for (const double lam : roots) {
        // Positive definite stiffness: matrix bulk modulus > 0 and E_L > 0 (kappa_f is
        // checked below), and the root must reproduce E_T (guards against lam ~ -mu).
        TransverselyIsotropicParams t = p;
        t.mu_T = mu;
        t.lambda = lam;
        const double d = E_f - young_isotropic(mu, lam);
        t.kappa_f = 0.5 * (d - 4.0 * (G_L - G_T));
        if (!(lam + 2.0 * mu / 3.0 > 0.0) || !(lam + mu > 0.0)) continue;
        const TransverselyIsotropicModuli m = small_strain_moduli(t);
        if (!(m.E_L > 0.0) || !(std::abs(m.E_T - E_T) <= 1e-8 * E_T)) continue;
        p = t;
        found = true;
        break;
      }
    }
    if (!found)
      bad_parameter(
          kTiEng, "E_T",
          "a value reachable with E_f = " + fmt(E_f) + " and G_T = " + fmt(G_T) + " (no positive definite lambda)",
          E_T);
    if (!(p.kappa_f >= 0.0))
      bad_parameter(kTiEng, "G_L", "a smaller value (kappa_f = " + fmt(p.kappa_f) + " < 0)", G_L);
  }
  p.validate();
  return p;
}

TransverselyIsotropic::TransverselyIsotropic(const TransverselyIsotropicParams& params, const Vec3& a0)
    : params_(params) {
  params_.validate();
  const double n = a0.norm();
  if (!std::isfinite(n) || !(n > 0.0)) bad_parameter(kTi, "fibre direction", "a nonzero vector", n);
  a0_ = a0 / n;
  const Mat3 A = a0_ * a0_.transpose();
  fibre_tangent_ = 2.0 * params_.kappa_f * outer(A, A) + 2.0 * (params_.mu_L - params_.mu_T) * d2_i5(a0_);
}

std::string TransverselyIsotropic::name() const {
  return params_.incompressible ? "transversely isotropic (incompressible)" : "transversely isotropic (compressible)";
}

MaterialResponse TransverselyIsotropic::evaluate(const Mat3& C, bool want_tangent) const {
  SF_ASSERT(detail::is_symmetric(C), "TransverselyIsotropic::evaluate: C must be symmetric");
  const TransverselyIsotropicParams& p = params_;
  const Vec3& a = a0_;
  const Vec3 b = C * a;
  const double i4 = a.dot(b);
  const double i5 = b.squaredNorm();
  const double c = p.mu_L - p.mu_T;
  const Mat3 A = a * a.transpose();
  const Mat3 ab = a * b.transpose();

  MaterialResponse r;
  r.energy =
      0.5 * p.mu_T * (C.trace() - 3.0) + 0.5 * c * (i5 - 2.0 * i4 + 1.0) + 0.25 * p.kappa_f * (i4 - 1.0) * (i4 - 1.0);
  r.stress = p.mu_T * Mat3::Identity() + c * (ab + ab.transpose() - 2.0 * A) + p.kappa_f * (i4 - 1.0) * A;
  if (want_tangent) r.tangent = fibre_tangent_;

  if (!p.incompressible) {
    const double det = C.determinant();
    if (!(det > 0.0)) return inverted_response();
    add_volumetric(C.inverse(), 0.5 * std::log(det), p.mu_T, p.lambda, want_tangent, r);
  }
  return r;
}

}  // namespace sf::forming
