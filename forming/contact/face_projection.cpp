#include "forming/contact/face_projection.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace sf::forming {
namespace {

constexpr double kTrust = 0.5;      // largest zeta step
constexpr double kZetaTol = 1e-13;  // converged step
constexpr int kMaxIterations = 40;
constexpr int kMaxHalvings = 50;

void evaluate(const FaceBasis& basis, const Eigen::Ref<const MatX>& pos, const Vec2& z, FaceFoot& f) {
  const FaceBasisValues v = basis.evaluate(z[0], z[1], true);
  f.zeta = z;
  f.x.setZero();
  f.x1.setZero();
  f.x2.setZero();
  f.x11.setZero();
  f.x12.setZero();
  f.x22.setZero();
  for (int a = 0; a < v.n; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const Vec3 xa = pos.row(a).transpose();
    f.x += v.value[i] * xa;
    f.x1 += v.ds[i] * xa;
    f.x2 += v.dt[i] * xa;
    f.x11 += v.dss[i] * xa;
    f.x12 += v.dst[i] * xa;
    f.x22 += v.dtt[i] * xa;
  }
}

}  // namespace

FaceFoot project_on_face(const FaceBasis& basis, const Eigen::Ref<const MatX>& pos, const Vec3& p) {
  FaceFoot f;
  // Start: the nearest of a 3 x 3 grid.
  double best = std::numeric_limits<double>::infinity();
  Vec2 start(0.5, 0.5);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const Vec2 z(0.5 * i, 0.5 * j);
      const std::array<double, 16>& value = basis.grid_values(i + 3 * j);
      Vec3 x = Vec3::Zero();
      for (int a = 0; a < basis.n_active(); ++a) x += value[static_cast<std::size_t>(a)] * pos.row(a).transpose();
      const double d = (p - x).squaredNorm();
      if (d < best) {
        best = d;
        start = z;
      }
    }
  evaluate(basis, pos, start, f);
  const double scale = p.cwiseAbs().maxCoeff() + 1.0;
  for (int it = 0; it < kMaxIterations; ++it) {
    const Vec3 r = p - f.x;
    const double fval = r.squaredNorm();
    const Vec2 g(-f.x1.dot(r), -f.x2.dot(r));
    bool fixed[2];
    for (int i = 0; i < 2; ++i) fixed[i] = (f.zeta[i] <= 0.0 && g[i] > 0.0) || (f.zeta[i] >= 1.0 && g[i] < 0.0);
    Mat2 gn;
    gn << f.x1.squaredNorm(), f.x1.dot(f.x2), f.x1.dot(f.x2), f.x2.squaredNorm();
    Mat2 h = gn;
    h(0, 0) -= r.dot(f.x11);
    h(1, 1) -= r.dot(f.x22);
    h(0, 1) -= r.dot(f.x12);
    h(1, 0) = h(0, 1);
    const bool pd = h(0, 0) > 0.0 && h(1, 1) > 0.0 && h.determinant() > 1e-14 * h(0, 0) * h(1, 1);
    const Mat2& use = pd ? h : gn;
    Vec2 d = Vec2::Zero();
    if (!fixed[0] && !fixed[1]) {
      d = -use.inverse() * g;
    } else if (!fixed[0]) {
      d[0] = -g[0] / use(0, 0);
    } else if (!fixed[1]) {
      d[1] = -g[1] / use(1, 1);
    }
    if (!d.allFinite()) d.setZero();
    if (d.norm() > kTrust) d *= kTrust / d.norm();
    bool accepted = false;
    for (int cut = 0; cut < kMaxHalvings; ++cut) {
      const Vec2 zt = (f.zeta + d).cwiseMax(0.0).cwiseMin(1.0);
      if ((zt - f.zeta).norm() <= kZetaTol) {
        f.converged = true;
        break;
      }
      FaceFoot trial;
      evaluate(basis, pos, zt, trial);
      const double ft = (p - trial.x).squaredNorm();
      const double noise = 64.0 * std::numeric_limits<double>::epsilon() * scale * (std::sqrt(fval) + std::sqrt(ft));
      if (ft <= fval + noise) {
        trial.converged = false;
        f = trial;
        accepted = true;
        break;
      }
      d *= 0.5;
    }
    if (f.converged) break;
    if (!accepted) {  // no decrease along a descent direction: stationary to round-off
      f.converged = true;
      break;
    }
  }
  const Vec3 r = p - f.x;
  f.distance = r.norm();
  // A bound with the gradient still pushing outward: the closest point lies beyond it.
  const Vec2 g(-f.x1.dot(r), -f.x2.dot(r));
  const double tol = 1e-9 * scale;
  for (int i = 0; i < 2 && f.exit_edge < 0; ++i) {
    const double tl = tol * std::max((i == 0 ? f.x1 : f.x2).norm(), 1e-300);
    if (f.zeta[i] <= 0.0 && g[i] > tl) f.exit_edge = 2 * i;
    if (f.zeta[i] >= 1.0 && g[i] < -tl) f.exit_edge = 2 * i + 1;
  }
  return f;
}

}  // namespace sf::forming
