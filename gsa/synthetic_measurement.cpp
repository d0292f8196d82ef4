#include "gsa/synthetic_measurement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "common/core/error.hpp"

namespace sf::gsa {

double NoiseModel::sigma_total() const {
  return std::sqrt(sigma_correlated * sigma_correlated + sigma_white * sigma_white);
}

ExactStrain Deformation::exact(const Vec3& X) const {
  const Mat32 g = gradient(X);
  const Mat2 C = g.transpose() * g;
  const double tr = C.trace(), det = C.determinant();
  const double d = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
  return {std::sqrt(tr / 2.0 + d), std::sqrt(std::max(0.0, tr / 2.0 - d))};
}

Deformation neck_deformation(double base, double peak, double w) {
  if (!(w > 0.0) || !(1.0 + base > 0.0) || !(1.0 + peak > 0.0))
    throw UsageError("neck: expected a positive width and stretches");
  Deformation d;
  d.name = "neck";
  d.description = "strip in tension along X, engineering strain " + std::to_string(base) + " with a neck of peak " +
                  std::to_string(peak) + " and width parameter " + std::to_string(w) + " mm at X = 0";
  auto lambda = [=](double X) { return 1.0 + base + (peak - base) * std::exp(-X * X / (2.0 * w * w)); };
  auto dlambda = [=](double X) { return -(peak - base) * X / (w * w) * std::exp(-X * X / (2.0 * w * w)); };
  d.map = [=](const Vec3& P) {
    const double X = P.x();
    const double x = (1.0 + base) * X + (peak - base) * w * std::sqrt(kPi / 2.0) * std::erf(X / (w * std::sqrt(2.0)));
    return Vec3(x, P.y() / std::sqrt(lambda(X)), 0.0);
  };
  d.gradient = [=](const Vec3& P) {
    const double l = lambda(P.x());
    const double dmu = -0.5 * std::pow(l, -1.5) * dlambda(P.x());
    Mat32 g;
    g << l, 0.0, P.y() * dmu, 1.0 / std::sqrt(l), 0.0, 0.0;
    return g;
  };
  return d;
}

Deformation band_deformation(double base, double peak, double w) {
  Deformation d = neck_deformation(base, peak, w);
  d.name = "band";
  d.description = "band of engineering strain " + std::to_string(peak) + " (width parameter " + std::to_string(w) +
                  " mm) along Y at X = 0 on " + std::to_string(base) + ", none across it";
  const auto neck_map = d.map;
  const auto neck_gradient = d.gradient;
  d.map = [=](const Vec3& P) { return Vec3(neck_map(P).x(), P.y(), 0.0); };
  d.gradient = [=](const Vec3& P) {
    Mat32 g = neck_gradient(P);
    g(1, 0) = 0.0, g(1, 1) = 1.0;
    return g;
  };
  return d;
}

Deformation dimple_deformation(double l1, double l2, double amplitude, double radius, double cx, double cy) {
  Deformation d;
  d.name = "dimple";
  d.description = "homogeneous stretch with an out-of-plane dimple of height " + std::to_string(amplitude) + " mm";
  auto bump = [=](double X, double Y) {
    return amplitude * std::exp(-((X - cx) * (X - cx) + (Y - cy) * (Y - cy)) / (2.0 * radius * radius));
  };
  d.map = [=](const Vec3& P) { return Vec3(l1 * P.x(), l2 * P.y(), bump(P.x(), P.y())); };
  d.gradient = [=](const Vec3& P) {
    const double b = bump(P.x(), P.y());
    Mat32 g;
    g << l1, 0.0, 0.0, l2, -b * (P.x() - cx) / (radius * radius), -b * (P.y() - cy) / (radius * radius);
    return g;
  };
  return d;
}

Deformation deformation_of(const SyntheticCase& c) {
  Deformation d;
  d.name = c.name;
  d.description = c.description;
  auto map = c.map;
  d.map = map;
  d.gradient = [map](const Vec3& P) {
    constexpr double h = 1e-3;
    Mat32 g;
    g.col(0) = (map(P + Vec3(h, 0, 0)) - map(P - Vec3(h, 0, 0))) / (2 * h);
    g.col(1) = (map(P + Vec3(0, h, 0)) - map(P - Vec3(0, h, 0))) / (2 * h);
    return g;
  };
  return d;
}

namespace {

struct LayoutPoint {
  Vec3 X;
  long i = -1, j = -1;
  double edge = 0.0;
};

std::vector<LayoutPoint> layout_points(const PointLayout& l, std::mt19937_64& rng) {
  if (!(l.spacing > 0.0) || !(l.length_x > 0.0) || !(l.length_y > 0.0))
    throw UsageError("synthetic layout: expected positive sizes and spacing");
  const long nx = std::max(2L, std::lround(l.length_x / l.spacing) + 1);
  const long ny = std::max(2L, std::lround(l.length_y / l.spacing) + 1);
  const double hx = 0.5 * l.length_x, hy = 0.5 * l.length_y;
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::vector<LayoutPoint> out;
  auto edge_distance = [&](const Vec3& X) {
    if (!l.round) return std::min(hx - std::abs(X.x()), hy - std::abs(X.y()));
    return (1.0 - std::hypot(X.x() / hx, X.y() / hy)) * std::min(hx, hy);
  };
  auto keep = [&](const Vec3& X) {
    return std::abs(X.x()) <= hx * (1 + 1e-12) && std::abs(X.y()) <= hy * (1 + 1e-12) &&
           (!l.round || std::hypot(X.x() / hx, X.y() / hy) <= 1.0 + 1e-12);
  };
  if (l.kind == PointLayout::Kind::kScattered) {
    const long n = nx * ny;
    for (long k = 0; k < n; ++k) {
      const Vec3 X(hx * uni(rng), hy * uni(rng), 0.0);
      if (keep(X)) out.push_back({X, -1, -1, edge_distance(X)});
    }
    return out;
  }
  const double sx = l.length_x / static_cast<double>(nx - 1), sy = l.length_y / static_cast<double>(ny - 1);
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i) {
      Vec3 X(-hx + i * sx, -hy + j * sy, 0.0);
      if (l.kind == PointLayout::Kind::kJittered) {
        X.x() += l.jitter * sx * uni(rng);
        X.y() += l.jitter * sy * uni(rng);
        X.x() = std::clamp(X.x(), -hx, hx);
        X.y() = std::clamp(X.y(), -hy, hy);
      }
      if (keep(X)) out.push_back({X, j, i, edge_distance(X)});
    }
  return out;
}

}  // namespace

SyntheticMeasurement make_measurement(const Deformation& deformation, const SyntheticMeasurementOptions& o) {
  std::mt19937_64 rng(o.seed);
  const std::vector<LayoutPoint> pts = layout_points(o.layout, rng);
  const CorrelatedField field_u(o.undeformed_noise.sigma_correlated, o.undeformed_noise.correlation_length,
                                2 * o.seed + 1);
  const CorrelatedField field_d(o.deformed_noise.sigma_correlated, o.deformed_noise.correlation_length, 2 * o.seed + 2);
  std::normal_distribution<double> normal(0.0, 1.0);
  SyntheticMeasurement m;
  const Index n = static_cast<Index>(pts.size());
  GridData& g = m.grid;
  g.sources = {"synthetic:" + deformation.name};
  g.ids.resize(n);
  g.where.assign(n, g.sources[0]);
  g.undeformed.resize(n, 3);
  g.deformed.resize(n, 3);
  g.has_ij = o.layout.kind != PointLayout::Kind::kScattered;
  if (g.has_ij) {
    g.i.resize(n);
    g.j.resize(n);
  }
  m.nominal.resize(n);
  m.exact.resize(n);
  m.edge_distance.resize(n);
  for (Index p = 0; p < n; ++p) {
    const LayoutPoint& lp = pts[p];
    g.ids[p] = "P" + std::to_string(p);
    if (g.has_ij) {
      g.i[p] = lp.i;
      g.j[p] = lp.j;
    }
    const Vec3 fu = field_u.at(lp.X), fd = field_d.at(lp.X), mx = deformation.map(lp.X);
    Vec3 X = lp.X + fu, x = mx + fd;
    for (int c = 0; c < 3; ++c) {
      const double wu = o.undeformed_noise.sigma_white * normal(rng), wd = o.deformed_noise.sigma_white * normal(rng);
      X[c] += wu;
      x[c] += wd;
      if (c == 2 && o.undeformed_noise.normal_factor != 1.0)
        X[2] = lp.X[2] + o.undeformed_noise.normal_factor * (fu[2] + wu);
      if (c == 2 && o.deformed_noise.normal_factor != 1.0) x[2] = mx[2] + o.deformed_noise.normal_factor * (fd[2] + wd);
    }
    g.undeformed.row(p) = X.transpose();
    g.deformed.row(p) = x.transpose();
    m.nominal[p] = lp.X;
    m.exact[p] = deformation.exact(lp.X);
    m.edge_distance[p] = lp.edge;
  }
  if (o.blunders > 0) {
    const double size = o.blunder_size > 0 ? o.blunder_size : 10.0 * std::max(o.deformed_noise.sigma_total(), 1e-3);
    std::uniform_int_distribution<Index> pick(0, n - 1);
    std::vector<bool> taken(static_cast<std::size_t>(n), false);
    for (int b = 0; b < o.blunders && b < n; ++b) {
      Index p = pick(rng);
      while (taken[p]) p = pick(rng);
      taken[p] = true;
      Vec3 dir(normal(rng), normal(rng), normal(rng));
      if (o.blunders_in_plane) dir[2] = 0.0;
      dir.normalize();
      g.deformed.row(p) += size * dir.transpose();
      m.blunder_points.push_back(p);
    }
  }
  return m;
}

}  // namespace sf::gsa
