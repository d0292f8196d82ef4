#include "gsa/digitise/raycast.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

namespace sf::gsa::digitise::synth {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// sin(x) / x, safe at 0.
double sinc(double x) { return std::abs(x) < 1e-6 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

}  // namespace

// ---------------------------------------------------------------------------------------
// Sheet

bool Sheet::contains(const Vec2& m) const {
  const Vec2 d = m - centre;
  return std::abs(d.x()) <= half_width && std::abs(d.y()) <= half_height && m.x() + m.y() <= trim;
}

namespace {

// Corner radius of the material rectangle and the z offset that puts the corners at z = 0.
double corner_radius(const Sheet& s) {
  const Vec2 a = s.centre.cwiseAbs() + Vec2(s.half_width, s.half_height);
  return a.norm();
}

// Position and normal in the sheet frame.
Vec3 local_position(const Sheet& s, const Vec2& m) {
  switch (s.shape) {
    case SheetShape::kFlat:
      return Vec3(m.x(), m.y(), 0.0);
    case SheetShape::kDome: {
      const double R = s.dome_radius, a = s.dome_stretch / R;
      const double r = m.norm(), phi = a * r;
      const double zc = -R * std::cos(a * corner_radius(s));
      const double k = R * a * sinc(phi);  // R sin(phi) / r
      return Vec3(k * m.x(), k * m.y(), R * std::cos(phi) + zc);
    }
    case SheetShape::kBend: {
      const double R = s.bend_radius;
      const double th = s.bend_stretch1 * m.x() / R;
      const double the = s.bend_stretch1 * (std::abs(s.centre.x()) + s.half_width) / R;
      return Vec3(R * std::sin(th), s.bend_stretch2 * m.y(), R * std::cos(th) - R * std::cos(the));
    }
  }
  return Vec3::Zero();
}

Vec3 local_normal(const Sheet& s, const Vec2& m) {
  switch (s.shape) {
    case SheetShape::kFlat:
      return Vec3(0, 0, 1);
    case SheetShape::kDome: {
      const double R = s.dome_radius, a = s.dome_stretch / R;
      const double r = m.norm(), phi = a * r;
      const double k = a * sinc(phi);  // sin(phi) / r
      return Vec3(k * m.x(), k * m.y(), std::cos(phi));
    }
    case SheetShape::kBend: {
      const double th = s.bend_stretch1 * m.x() / s.bend_radius;
      return Vec3(std::sin(th), 0, std::cos(th));
    }
  }
  return Vec3(0, 0, 1);
}

}  // namespace

Vec3 Sheet::position(const Vec2& m) const { return R * local_position(*this, m) + t; }
Vec3 Sheet::normal(const Vec2& m) const { return R * local_normal(*this, m); }

std::pair<double, double> Sheet::stretches(const Vec2& m) const {
  switch (shape) {
    case SheetShape::kFlat:
      return {1.0, 1.0};
    case SheetShape::kDome: {
      const double R = dome_radius, a = dome_stretch / R;
      const double lm = R * a, lc = R * a * sinc(a * m.norm());
      return {std::max(lm, lc), std::min(lm, lc)};
    }
    case SheetShape::kBend:
      return {std::max(bend_stretch1, bend_stretch2), std::min(bend_stretch1, bend_stretch2)};
  }
  return {1.0, 1.0};
}

std::optional<Sheet::Hit> Sheet::intersect(const Vec3& ow, const Vec3& dw) const {
  const Vec3 o = R.transpose() * (ow - t), d = R.transpose() * dw;
  auto finish = [&](double dist, const Vec2& m, const Vec3& n_local) -> std::optional<Hit> {
    if (!(dist > 1e-9) || !contains(m)) return std::nullopt;
    Hit h;
    h.distance = dist;
    h.m = m;
    h.normal = R * n_local;
    h.front = n_local.dot(d) < 0;
    return h;
  };
  switch (shape) {
    case SheetShape::kFlat: {
      if (d.z() == 0) return std::nullopt;
      const double dist = -o.z() / d.z();
      const Vec3 p = o + dist * d;
      return finish(dist, Vec2(p.x(), p.y()), Vec3(0, 0, 1));
    }
    case SheetShape::kDome: {
      const double Rs = dome_radius, a = dome_stretch / Rs;
      const Vec3 c(0, 0, -Rs * std::cos(a * corner_radius(*this)));
      const Vec3 oc = o - c;
      const double b = oc.dot(d), cc = oc.squaredNorm() - Rs * Rs;
      const double disc = b * b - cc;
      if (disc < 0) return std::nullopt;
      const double sq = std::sqrt(disc);
      for (double dist : {-b - sq, -b + sq}) {
        if (!(dist > 1e-9)) continue;
        const Vec3 q = oc + dist * d;
        const double rho = std::hypot(q.x(), q.y());
        const double phi = std::atan2(rho, q.z());
        // material radius r = phi / a; direction (q.x, q.y) / rho
        const double k = rho > 0 ? phi / (a * rho) : 1.0 / (a * Rs);
        const Vec2 m(k * q.x(), k * q.y());
        if (auto h = finish(dist, m, q / Rs)) return h;
      }
      return std::nullopt;
    }
    case SheetShape::kBend: {
      const double Rb = bend_radius;
      const double the = bend_stretch1 * (std::abs(centre.x()) + half_width) / Rb;
      const double zc = -Rb * std::cos(the);
      // (o.x + s d.x)^2 + (o.z - zc + s d.z)^2 = R^2
      const double ox = o.x(), oz = o.z() - zc;
      const double A = d.x() * d.x() + d.z() * d.z();
      if (A < 1e-300) return std::nullopt;
      const double B = ox * d.x() + oz * d.z(), C = ox * ox + oz * oz - Rb * Rb;
      const double disc = B * B - A * C;
      if (disc < 0) return std::nullopt;
      const double sq = std::sqrt(disc);
      for (double dist : {(-B - sq) / A, (-B + sq) / A}) {
        if (!(dist > 1e-9)) continue;
        const Vec3 p = o + dist * d;
        const double th = std::atan2(p.x(), p.z() - zc);
        const Vec2 m(Rb * th / bend_stretch1, p.y() / bend_stretch2);
        if (auto h = finish(dist, m, Vec3(std::sin(th), 0, std::cos(th)))) return h;
      }
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------
// Pattern

namespace {

int clampi(long v, int lo, int hi) { return static_cast<int>(std::clamp<long>(v, lo, hi)); }

// Index of the nearest multiple of `pitch` to x, clamped to [lo, hi].
int nearest_index(double x, double pitch, int lo, int hi) { return clampi(std::lround(x / pitch), lo, hi); }

}  // namespace

double Pattern::reflectance(const Vec2& m) const {
  const double p = pitch;
  switch (kind) {
    case PatternKind::kDots: {
      const int i = nearest_index(m.x(), p, i_min, i_max), j = nearest_index(m.y(), p, j_min, j_max);
      const bool ref = reference && i == 0 && j == 0;
      const double r = 0.5 * (ref ? reference_diameter : dot_diameter);
      return (m - Vec2(i * p, j * p)).squaredNorm() <= r * r ? ink : paper;
    }
    case PatternKind::kLines: {
      const double h = 0.5 * line_width;
      const double x0 = i_min * p - 0.5 * p, x1 = i_max * p + 0.5 * p;
      const double y0 = j_min * p - 0.5 * p, y1 = j_max * p + 0.5 * p;
      const bool in_x = m.x() >= x0 && m.x() <= x1, in_y = m.y() >= y0 && m.y() <= y1;
      if (in_y && std::abs(m.x() - nearest_index(m.x(), p, i_min, i_max) * p) <= h) return ink;
      if (in_x && std::abs(m.y() - nearest_index(m.y(), p, j_min, j_max) * p) <= h) return ink;
      if (reference && (m - Vec2(0.5 * p, 0.5 * p)).squaredNorm() <= 0.25 * reference_diameter * reference_diameter)
        return ink;
      return paper;
    }
    case PatternKind::kChessboard: {
      // Squares (a, b), a in [-1, cols], b in [-1, rows], span [a p, (a + 1) p] x ...; black when
      // a + b is even. Inner corners at (k p, l p).
      const double a = std::floor(m.x() / p), b = std::floor(m.y() / p);
      if (a < -1 || a > cols || b < -1 || b > rows) return paper;
      return (static_cast<long>(a + b) % 2 == 0) ? ink : paper;
    }
    case PatternKind::kCircles:
    case PatternKind::kAsymmetricCircles: {
      const double r = 0.5 * dot_diameter;
      const int l = nearest_index(m.y(), p, 0, rows - 1);
      for (int dl = -1; dl <= 1; ++dl) {
        const int ll = l + dl;
        if (ll < 0 || ll >= rows) continue;
        const double shift = kind == PatternKind::kAsymmetricCircles ? (ll % 2) * p : 0.0;
        const double step = kind == PatternKind::kAsymmetricCircles ? 2 * p : p;
        const int k = clampi(std::lround((m.x() - shift) / step), 0, cols - 1);
        if ((m - Vec2(k * step + shift, ll * p)).squaredNorm() <= r * r) return ink;
      }
      return paper;
    }
  }
  return paper;
}

double Pattern::edge_distance(const Vec2& m) const {
  const double p = pitch;
  switch (kind) {
    case PatternKind::kDots: {
      // Nodes of the 3 x 3 block around the nearest lattice point; every other node is at
      // least one pitch away, so at least (pitch - the largest radius) from any dot edge.
      const long i0 = std::lround(m.x() / p), j0 = std::lround(m.y() / p);
      const double r_max = 0.5 * std::max(dot_diameter, reference ? reference_diameter : 0.0);
      double e = p - r_max;
      for (long j = j0 - 1; j <= j0 + 1; ++j)
        for (long i = i0 - 1; i <= i0 + 1; ++i) {
          if (i < i_min || i > i_max || j < j_min || j > j_max) continue;
          const double r = 0.5 * ((reference && i == 0 && j == 0) ? reference_diameter : dot_diameter);
          e = std::min(e, std::abs((m - Vec2(i * p, j * p)).norm() - r));
        }
      return std::max(0.0, e);
    }
    case PatternKind::kLines: {
      const double h = 0.5 * line_width;
      const double dx = std::abs(m.x() - nearest_index(m.x(), p, i_min, i_max) * p);
      const double dy = std::abs(m.y() - nearest_index(m.y(), p, j_min, j_max) * p);
      const double x0 = i_min * p - 0.5 * p, x1 = i_max * p + 0.5 * p;
      const double y0 = j_min * p - 0.5 * p, y1 = j_max * p + 0.5 * p;
      double e = std::min(std::abs(dx - h), std::abs(dy - h));
      e = std::min({e, std::abs(m.x() - x0), std::abs(m.x() - x1), std::abs(m.y() - y0), std::abs(m.y() - y1)});
      if (reference) e = std::min(e, std::abs((m - Vec2(0.5 * p, 0.5 * p)).norm() - 0.5 * reference_diameter));
      return e;
    }
    case PatternKind::kChessboard: {
      const double dx = std::abs(m.x() - std::round(m.x() / p) * p);
      const double dy = std::abs(m.y() - std::round(m.y() / p) * p);
      return std::min(dx, dy);
    }
    case PatternKind::kCircles:
    case PatternKind::kAsymmetricCircles: {
      const double r = 0.5 * dot_diameter;
      double e = kInf;
      const int l = nearest_index(m.y(), p, 0, rows - 1);
      for (int dl = -1; dl <= 1; ++dl) {
        const int ll = l + dl;
        if (ll < 0 || ll >= rows) continue;
        const double shift = kind == PatternKind::kAsymmetricCircles ? (ll % 2) * p : 0.0;
        const double step = kind == PatternKind::kAsymmetricCircles ? 2 * p : p;
        const int k = clampi(std::lround((m.x() - shift) / step), 0, cols - 1);
        for (int dk = -1; dk <= 1; ++dk) {
          const int kk = k + dk;
          if (kk < 0 || kk >= cols) continue;
          e = std::min(e, std::abs((m - Vec2(kk * step + shift, ll * p)).norm() - r));
        }
      }
      return e;
    }
  }
  return 0.0;
}

namespace {

// Fraction of a Gaussian (standard deviation sigma) beyond a signed distance: a blurred
// step. d > 0 inside.
double smooth_step(double d, double sigma) {
  if (!(sigma > 0)) return d >= 0 ? 1.0 : 0.0;
  return 0.5 * std::erfc(-d / (std::sqrt(2.0) * sigma));
}
// A blurred interval [lo, hi] along one coordinate.
double smooth_band(double x, double lo, double hi, double sigma) {
  return smooth_step(x - lo, sigma) - smooth_step(x - hi, sigma);
}

}  // namespace

double Pattern::blurred_reflectance(const Vec2& m, const Mat2& blur) const {
  const double p = pitch;
  // Standard deviation of the blur along a material unit direction n: |blur^T n|.
  auto sigma_along = [&](const Vec2& n) { return (blur.transpose() * n).norm(); };
  const double sx = sigma_along(Vec2(1, 0)), sy = sigma_along(Vec2(0, 1));
  // A blurred disc: an error function across its edge, whose half-level circle sits
  // sigma^2 / 2r inside the edge (the convolution of a curved edge), so the blurred disc
  // keeps the disc's area to O(sigma^4 / r^2).
  auto disc = [&](const Vec2& c, double r) {
    const Vec2 d = m - c;
    const double dist = d.norm();
    const Vec2 n = dist > 1e-12 ? Vec2(d / dist) : Vec2(1, 0);
    const double s = sigma_along(n);
    return smooth_step(r - s * s / (2 * r) - dist, s);
  };
  double ink_fraction = 0;
  switch (kind) {
    case PatternKind::kDots: {
      const int i = nearest_index(m.x(), p, i_min, i_max), j = nearest_index(m.y(), p, j_min, j_max);
      const bool ref = reference && i == 0 && j == 0;
      ink_fraction = disc(Vec2(i * p, j * p), 0.5 * (ref ? reference_diameter : dot_diameter));
      break;
    }
    case PatternKind::kLines: {
      const double h = 0.5 * line_width;
      const double x0 = i_min * p - 0.5 * p, x1 = i_max * p + 0.5 * p;
      const double y0 = j_min * p - 0.5 * p, y1 = j_max * p + 0.5 * p;
      const double xi = nearest_index(m.x(), p, i_min, i_max) * p, yj = nearest_index(m.y(), p, j_min, j_max) * p;
      const double v = smooth_band(m.x(), xi - h, xi + h, sx) * smooth_band(m.y(), y0, y1, sy);
      const double hz = smooth_band(m.y(), yj - h, yj + h, sy) * smooth_band(m.x(), x0, x1, sx);
      ink_fraction = v + hz - v * hz;
      if (reference) {
        const double d = disc(Vec2(0.5 * p, 0.5 * p), 0.5 * reference_diameter);
        ink_fraction = ink_fraction + d - ink_fraction * d;
      }
      break;
    }
    case PatternKind::kChessboard: {
      // Square waves S = +-1 along X and Y, each blurred across its nearest edge; black where
      // S_X S_Y = +1, inside the board.
      const long kx = std::lround(m.x() / p), ky = std::lround(m.y() / p);
      const double Sx =
          ((kx % 2 == 0) ? 1.0 : -1.0) * std::erf((m.x() - kx * p) / (std::sqrt(2.0) * std::max(sx, 1e-12)));
      const double Sy =
          ((ky % 2 == 0) ? 1.0 : -1.0) * std::erf((m.y() - ky * p) / (std::sqrt(2.0) * std::max(sy, 1e-12)));
      const double inside = smooth_band(m.x(), -p, (cols + 1) * p, sx) * smooth_band(m.y(), -p, (rows + 1) * p, sy);
      ink_fraction = 0.5 * (1.0 + Sx * Sy) * inside;
      break;
    }
    case PatternKind::kCircles:
    case PatternKind::kAsymmetricCircles: {
      const double r = 0.5 * dot_diameter;
      const int l = nearest_index(m.y(), p, 0, rows - 1);
      for (int dl = -1; dl <= 1; ++dl) {
        const int ll = l + dl;
        if (ll < 0 || ll >= rows) continue;
        const double shift = kind == PatternKind::kAsymmetricCircles ? (ll % 2) * p : 0.0;
        const double step = kind == PatternKind::kAsymmetricCircles ? 2 * p : p;
        const int k = clampi(std::lround((m.x() - shift) / step), 0, cols - 1);
        ink_fraction = std::max(ink_fraction, disc(Vec2(k * step + shift, ll * p), r));
      }
      break;
    }
  }
  return paper + (ink - paper) * ink_fraction;
}

std::vector<Pattern::Mark> Pattern::marks() const {
  std::vector<Mark> out;
  const double p = pitch;
  switch (kind) {
    case PatternKind::kDots:
    case PatternKind::kLines:
      for (int j = j_min; j <= j_max; ++j)
        for (int i = i_min; i <= i_max; ++i) out.push_back({i, j, Vec2(i * p, j * p)});
      break;
    case PatternKind::kChessboard:
    case PatternKind::kCircles:
      for (int l = 0; l < rows; ++l)
        for (int k = 0; k < cols; ++k) out.push_back({k, l, Vec2(k * p, l * p)});
      break;
    case PatternKind::kAsymmetricCircles:
      for (int l = 0; l < rows; ++l)
        for (int k = 0; k < cols; ++k) out.push_back({k, l, Vec2((2 * k + l % 2) * p, l * p)});
      break;
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Rendering

namespace {

constexpr int kBackground = 0, kFront = 1, kBack = 2, kOccluder = 3;

struct Sample {
  int id = kBackground;  // kBackground, kFront, kBack, kOccluder + k
  Vec2 m = Vec2::Zero();
  double shade = 1.0;
};

struct Caster {
  const Camera& cam;
  const Scene& scene;
  Vec3 origin;
  Mat3 Rt;

  Sample cast(const Vec2& xn) const {
    const Vec3 d = (Rt * Vec3(xn.x(), xn.y(), 1.0)).normalized();
    Sample s;
    double best = kInf;
    if (auto h = scene.sheet.intersect(origin, d)) {
      best = h->distance;
      s.id = h->front ? kFront : kBack;
      s.m = h->m;
      const Vec3 n = h->front ? h->normal : Vec3(-h->normal);
      const Lighting& L = scene.lighting;
      s.shade = L.ambient + L.diffuse * std::max(0.0, n.dot(L.light));
    }
    for (std::size_t k = 0; k < scene.occluders.size(); ++k) {
      const Occluder& oc = scene.occluders[k];
      const Vec3 n = oc.edge1.cross(oc.edge2);
      const double dn = d.dot(n);
      if (std::abs(dn) < 1e-300) continue;
      const double dist = (oc.corner - origin).dot(n) / dn;
      if (!(dist > 1e-9) || dist >= best) continue;
      const Vec3 q = origin + dist * d - oc.corner;
      Mat2 G;
      G << oc.edge1.dot(oc.edge1), oc.edge1.dot(oc.edge2), oc.edge1.dot(oc.edge2), oc.edge2.dot(oc.edge2);
      const Vec2 ab = G.inverse() * Vec2(q.dot(oc.edge1), q.dot(oc.edge2));
      if (ab.x() < 0 || ab.x() > 1 || ab.y() < 0 || ab.y() > 1) continue;
      best = dist;
      s.id = kOccluder + static_cast<int>(k);
      s.shade = 1.0;
    }
    return s;
  }

  double grey(const Sample& s) const {
    switch (s.id) {
      case kBackground:
        return scene.lighting.background;
      case kFront:
        return scene.pattern.reflectance(s.m) * s.shade * scene.lighting.exposure;
      case kBack:
        return scene.pattern.paper * s.shade * scene.lighting.exposure;
      default:
        return scene.occluders[s.id - kOccluder].grey * scene.lighting.exposure;
    }
  }
};

struct Corner {
  Vec2 xn;
  Sample s;
};

// Sub-pixel sample positions in [0, 1]^2: a Fibonacci lattice (k / F, frac(k G / F)) with
// F >= N^2 points. Unlike an N x N grid it has F distinct positions along every axis (and
// nearly along every direction), so an edge parallel to the pixel rows is resolved to
// 1/F of a pixel rather than 1/N: no "pixel locking" of edge positions in the pictures.
std::vector<Vec2> sample_pattern(int n) {
  long f0 = 8, f1 = 13;
  while (f1 < static_cast<long>(n) * n) {
    const long f2 = f0 + f1;
    f0 = f1;
    f1 = f2;
  }
  std::vector<Vec2> out;
  out.reserve(f1);
  for (long k = 0; k < f1; ++k) {
    const double y = std::fmod((k * f0 + 0.5) / static_cast<double>(f1), 1.0);
    out.emplace_back((k + 0.5) / f1, y);
  }
  return out;
}

void render_rows(const Caster& caster, const Effects& fx, int r0, int r1, GreyImage& out) {
  const Camera& cam = caster.cam;
  const int W = cam.width;
  // Blurred patterns are smooth at the pixel scale: a lattice rule of ~21 points
  // integrates them to far better than the 8-bit grey levels.
  const int n_side = fx.blur_sigma >= 0.3 ? std::min(std::max(1, fx.supersampling), 4) : std::max(1, fx.supersampling);
  const std::vector<Vec2> samples = sample_pattern(n_side);
  const std::vector<Vec2> sharp_samples = sample_pattern(std::max(1, fx.supersampling));
  const double n_samples = static_cast<double>(samples.size());
  const Pattern& pat = caster.scene.pattern;
  std::vector<Corner> above(W + 1), below(W + 1);
  auto corner_row = [&](int r, std::vector<Corner>& row) {
    const double v = r - 0.5;
    for (int c = 0; c <= W; ++c) {
      const double u = c - 0.5;
      row[c].xn = cam.undistort(Vec2((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy));
      row[c].s = caster.cast(row[c].xn);
    }
  };
  corner_row(r0, above);
  for (int r = r0; r < r1; ++r) {
    corner_row(r + 1, below);
    for (int c = 0; c < W; ++c) {
      const Corner* k[4] = {&above[c], &above[c + 1], &below[c], &below[c + 1]};  // 00, 10, 01, 11
      const int id = k[0]->s.id;
      const bool same = k[1]->s.id == id && k[2]->s.id == id && k[3]->s.id == id;
      double value = 0;
      if (same && id != kFront) {
        Sample s = k[0]->s;
        s.shade = 0.25 * (k[0]->s.shade + k[1]->s.shade + k[2]->s.shade + k[3]->s.shade);
        value = caster.grey(s);
      } else if (same) {
        const Vec2 mc = 0.25 * (k[0]->s.m + k[1]->s.m + k[2]->s.m + k[3]->s.m);
        double foot = 0;
        for (const Corner* q : k) foot = std::max(foot, (q->s.m - mc).norm());
        const double shade = 0.25 * (k[0]->s.shade + k[1]->s.shade + k[2]->s.shade + k[3]->s.shade);
        // Optical blur in material coordinates: sigma x d(material)/d(pixel) of this pixel.
        Mat2 blur = Mat2::Zero();
        double reach = 0;  // how far (material) the blur reaches: 4 sigma
        if (fx.blur_sigma > 0) {
          blur.col(0) = 0.5 * (k[1]->s.m - k[0]->s.m + k[3]->s.m - k[2]->s.m) * fx.blur_sigma;
          blur.col(1) = 0.5 * (k[2]->s.m - k[0]->s.m + k[3]->s.m - k[1]->s.m) * fx.blur_sigma;
          reach = 4.0 * blur.norm();
        }
        double refl;
        if (pat.edge_distance(mc) > 1.05 * foot + reach + 1e-12) {
          refl = pat.reflectance(mc);
        } else {
          double sum = 0;
          for (const Vec2& ab : samples) {
            const double a = ab.x(), b = ab.y();
            const Vec2 m = (1 - b) * ((1 - a) * k[0]->s.m + a * k[1]->s.m) + b * ((1 - a) * k[2]->s.m + a * k[3]->s.m);
            sum += fx.blur_sigma > 0 ? pat.blurred_reflectance(m, blur) : pat.reflectance(m);
          }
          refl = sum / n_samples;
        }
        value = refl * shade * caster.scene.lighting.exposure;
      } else {
        double sum = 0;
        for (const Vec2& ab : sharp_samples) {
          const double a = ab.x(), b = ab.y();
          sum += caster.grey(
              caster.cast((1 - b) * ((1 - a) * k[0]->xn + a * k[1]->xn) + b * ((1 - a) * k[2]->xn + a * k[3]->xn)));
        }
        value = sum / static_cast<double>(sharp_samples.size());
      }
      out.at(c, r) = static_cast<float>(value);
    }
    std::swap(above, below);
  }
}

}  // namespace

GreyImage render(const Camera& camera, const Scene& scene, const Effects& fx) {
  GreyImage img(camera.width, camera.height);
  const Caster caster{camera, scene, camera.centre(), camera.R.transpose()};
  int n_threads = fx.threads > 0 ? fx.threads : static_cast<int>(std::thread::hardware_concurrency());
  n_threads = std::clamp(n_threads, 1, std::max(1, camera.height / 16));
  std::vector<std::thread> pool;
  for (int k = 0; k < n_threads; ++k) {
    const int r0 = static_cast<int>(static_cast<long>(camera.height) * k / n_threads);
    const int r1 = static_cast<int>(static_cast<long>(camera.height) * (k + 1) / n_threads);
    pool.emplace_back([&, r0, r1] { render_rows(caster, fx, r0, r1, img); });
  }
  for (auto& t : pool) t.join();

  // Uneven lighting over the image.
  const Lighting& L = scene.lighting;
  if (L.gradient != 0 || L.vignetting != 0) {
    const double hw = 0.5 * camera.width, hh = 0.5 * camera.height, rc2 = hw * hw + hh * hh;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const double dx = x + 0.5 - hw, dy = y + 0.5 - hh;
        const double f = (1.0 - L.gradient * (x + 0.5) / img.width) * (1.0 - L.vignetting * (dx * dx + dy * dy) / rc2);
        img.at(x, y) = static_cast<float>(img.at(x, y) * f);
      }
  }
  if (fx.noise_sigma > 0) {
    std::mt19937 rng(fx.seed);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(fx.noise_sigma));
    for (float& v : img.pixels) v += noise(rng);
  }
  const double levels = fx.quantise_bits == 8 ? 255.0 : fx.quantise_bits == 16 ? 65535.0 : 0.0;
  for (float& v : img.pixels) {
    v = std::clamp(v, 0.0f, 1.0f);
    if (levels > 0) v = static_cast<float>(std::round(v * levels) / levels);
  }
  return img;
}

}  // namespace sf::gsa::digitise::synth
