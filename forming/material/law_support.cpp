#include "forming/material/law_support.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/core/error.hpp"

namespace sf::forming::detail {

void bad_parameter(const std::string& law, const std::string& parameter, const std::string& expected, double found) {
  std::ostringstream os;
  os.precision(10);
  os << law << " " << parameter << ": expected " << expected << ", found " << found;
  throw InputError(os.str());
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

void require_finite(const std::string& law, const std::string& parameter, double v) {
  if (!std::isfinite(v)) bad_parameter(law, parameter, "a finite number", v);
}

void require_positive(const std::string& law, const std::string& parameter, double v) {
  require_finite(law, parameter, v);
  if (!(v > 0.0)) bad_parameter(law, parameter, "a positive value (MPa)", v);
}

Mat6 outer(const Mat3& X, const Mat3& Y) { return voigt_stress(X) * voigt_stress(Y).transpose(); }

Mat6 sym_product(const Mat3& X) {
  Mat6 m;
  for (int I = 0; I < 6; ++I) {
    const int i = kVoigtPair[I][0], j = kVoigtPair[I][1];
    for (int K = 0; K < 6; ++K) {
      const int k = kVoigtPair[K][0], l = kVoigtPair[K][1];
      m(I, K) = 0.5 * (X(i, k) * X(j, l) + X(i, l) * X(j, k));
    }
  }
  return m;
}

MaterialResponse inverted_response() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  MaterialResponse r;
  r.energy = std::numeric_limits<double>::infinity();
  r.stress.setConstant(nan);
  r.tangent.setConstant(nan);
  return r;
}

bool is_symmetric(const Mat3& C) {
  return (C - C.transpose()).cwiseAbs().maxCoeff() <= 1e-10 * (1.0 + C.cwiseAbs().maxCoeff());
}

void add_volumetric(const Mat3& Ci, double ln_j, double mu, double lambda, bool want_tangent, MaterialResponse& r) {
  r.energy += -mu * ln_j + 0.5 * lambda * ln_j * ln_j;
  r.stress += (lambda * ln_j - mu) * Ci;
  if (!want_tangent) return;
  // lambda outer(Ci, Ci) + 2 (mu - lambda ln J) sym_product(Ci), entry by entry with the
  // same operations (no Mat6 temporaries).
  const double s = 2.0 * (mu - lambda * ln_j);
  double v[6];
  for (int I = 0; I < 6; ++I) v[I] = Ci(kVoigtPair[I][0], kVoigtPair[I][1]);
  for (int K = 0; K < 6; ++K) {
    const int k = kVoigtPair[K][0], l = kVoigtPair[K][1];
    for (int I = 0; I < 6; ++I) {
      const int i = kVoigtPair[I][0], j = kVoigtPair[I][1];
      r.tangent(I, K) += lambda * (v[I] * v[K]) + s * (0.5 * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k)));
    }
  }
}

bool add_isotropic_volumetric(const char* law, const Mat3& C, double m, double lambda, bool want_tangent,
                              MaterialResponse& r) {
  (void)law;  // named in the debug check
  SF_ASSERT(is_symmetric(C), std::string(law) + "::evaluate: C must be symmetric");
  const double det = C.determinant();
  if (!(det > 0.0)) return false;
  add_volumetric(C.inverse(), 0.5 * std::log(det), m, lambda, want_tangent, r);
  return true;
}

double young_isotropic(double mu, double lambda) { return mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu); }

}  // namespace sf::forming::detail
