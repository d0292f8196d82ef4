#include "gsa/neck.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace sf::gsa {

namespace {
// Least-squares quadratic q(s) = a s^2 + b s + c through (s, y), s taken about `origin`.
Eigen::Vector3d quadratic(const std::vector<double>& s, const std::vector<double>& y, double origin) {
  Eigen::MatrixXd A(static_cast<Eigen::Index>(s.size()), 3);
  Eigen::VectorXd b(static_cast<Eigen::Index>(s.size()));
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double x = s[i] - origin;
    A.row(static_cast<Eigen::Index>(i)) << x * x, x, 1.0;
    b[static_cast<Eigen::Index>(i)] = y[i];
  }
  return A.colPivHouseholderQr().solve(b);
}
}  // namespace

NeckResult evaluate_neck(const std::vector<double>& s_in, const std::vector<double>& major_in,
                         const std::vector<double>& minor_in) {
  NeckResult r;
  std::vector<double> s, e1, e2;
  for (std::size_t i = 0; i < s_in.size() && i < major_in.size() && i < minor_in.size(); ++i)
    if (std::isfinite(s_in[i]) && std::isfinite(major_in[i]) && std::isfinite(minor_in[i]) &&
        (s.empty() || s_in[i] > s.back())) {
      s.push_back(s_in[i]);
      e1.push_back(major_in[i]);
      e2.push_back(minor_in[i]);
    }
  const std::size_t n = s.size();
  if (n < 9) {
    r.message = "too few points along the section (" + std::to_string(n) + ", need 9)";
    return r;
  }
  const std::size_t p = static_cast<std::size_t>(std::max_element(e1.begin(), e1.end()) - e1.begin());
  r.peak_position = s[p];
  r.peak_major = e1[p];
  if (!(e1[p] > 0)) {
    r.message = "no tensile major strain along the section";
    return r;
  }
  const double beta = std::clamp(e2[p] / e1[p], -0.5, 1.0);
  const double W = 10.0 * (1.0 + beta);
  r.window_width = W;
  // Second derivative along s (non-uniform central differences); NaN at the ends.
  std::vector<double> d2(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double h0 = s[i] - s[i - 1], h1 = s[i + 1] - s[i];
    d2[i] = 2.0 * (h0 * e1[i + 1] - (h0 + h1) * e1[i] + h1 * e1[i - 1]) / (h0 * h1 * (h0 + h1));
  }
  auto shoulder = [&](int dir) -> long {
    long best = -1;
    for (long i = static_cast<long>(p) + dir; i > 0 && i + 1 < static_cast<long>(n); i += dir) {
      if (std::abs(s[static_cast<std::size_t>(i)] - s[p]) > W) break;
      if (best < 0 || d2[static_cast<std::size_t>(i)] > d2[static_cast<std::size_t>(best)]) best = i;
    }
    return best;
  };
  const long il = shoulder(-1), ir = shoulder(+1);
  if (il < 0 || ir < 0) {
    r.message = "the neck at s = " + std::to_string(s[p]) + " is too close to an end of the section";
    return r;
  }
  r.inner_left = s[static_cast<std::size_t>(il)];
  r.inner_right = s[static_cast<std::size_t>(ir)];
  std::vector<double> fs, f1, f2;
  int left = 0, right = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Strictly outside the boundaries, and one point further: the boundary's central
    // difference reaches one point into the neck.
    const long li = static_cast<long>(i);
    const bool in_left = li < il - 1 && s[i] >= r.inner_left - W;
    const bool in_right = li > ir + 1 && s[i] <= r.inner_right + W;
    if (!in_left && !in_right) continue;
    if (!(e1[i] > 0)) continue;
    (in_left ? left : right) += 1;
    fs.push_back(s[i]);
    f1.push_back(1.0 / e1[i]);
    f2.push_back(e2[i]);
  }
  if (left < 3 || right < 3) {
    r.message = "fewer than 3 points in a fit window (" + std::to_string(left) + " left, " + std::to_string(right) +
                " right of the neck)";
    return r;
  }
  r.outer_left = std::max(s.front(), r.inner_left - W);
  r.outer_right = std::min(s.back(), r.inner_right + W);
  r.fit_points = left + right;
  const double origin = s[p];
  const Eigen::Vector3d q = quadratic(fs, f1, origin);
  if (!(q[0] > 0)) {
    r.message =
        "the inverse parabola fitted either side of the neck has no maximum (the strain does not rise "
        "toward the neck)";
    return r;
  }
  const double x = -q[1] / (2 * q[0]);
  const double inv = q[2] - q[1] * q[1] / (4 * q[0]);
  if (!(inv > 0)) {
    r.message = "the fitted inverse parabola's apex is not a finite positive strain";
    return r;
  }
  r.apex_position = origin + x;
  r.limit_major = 1.0 / inv;
  const Eigen::Vector3d m = quadratic(fs, f2, origin);
  r.limit_minor = m[0] * x * x + m[1] * x + m[2];
  double ss = 0;
  for (std::size_t i = 0; i < fs.size(); ++i) {
    const double xi = fs[i] - origin;
    const double fit = 1.0 / (q[0] * xi * xi + q[1] * xi + q[2]);
    ss += (fit - 1.0 / f1[i]) * (fit - 1.0 / f1[i]);
  }
  r.fit_rms = std::sqrt(ss / static_cast<double>(fs.size()));
  // A neck is a localisation: the measured peak stands above the smooth background fitted
  // either side. Without one the "limit" would only be the background's own maximum.
  if (!(r.peak_major > 1.02 * r.limit_major)) {
    std::ostringstream why;
    why << "no localised neck: the peak major strain " << r.peak_major << " is within 2 % of the strain fitted "
        << "either side at the apex (" << r.limit_major << ")";
    r.message = why.str();
    return r;
  }
  r.ok = true;
  return r;
}

}  // namespace sf::gsa
