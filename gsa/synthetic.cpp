#include "gsa/synthetic.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "common/core/error.hpp"

namespace sf::gsa {

namespace {

// Rigid motion: rotation about an oblique axis plus translation.
Mat3 rotation() { return (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())).toRotationMatrix(); }
Vec3 rigid_map(const Vec3& X) { return rotation() * X + Vec3(10, -5, 3); }
ExactStrain rigid_exact(const Vec3&) { return {1.0, 1.0}; }

// Homogeneous biaxial stretch (1.2, 0.9) then a rotation.
Vec3 stretch_map(const Vec3& X) { return rotation() * Vec3(1.2 * X.x(), 0.9 * X.y(), 0.0); }
ExactStrain stretch_exact(const Vec3&) { return {1.2, 0.9}; }

// Simple shear x = X + k Y: principal stretches from C = [[1, k], [k, 1 + k^2]].
constexpr double kShear = 0.3;
Vec3 shear_map(const Vec3& X) { return Vec3(X.x() + kShear * X.y(), X.y(), 0.0); }
ExactStrain shear_exact(const Vec3&) {
  const double tr = 2.0 + kShear * kShear, det = 1.0;
  const double d = std::sqrt(tr * tr / 4.0 - det);
  return {std::sqrt(tr / 2.0 + d), std::sqrt(tr / 2.0 - d)};
}

// Stretch (1.08 along X, 0.97 along Y) then isometric bending onto a cylinder R = 60 mm.
constexpr double kCylR = 60.0;
Vec3 cylinder_map(const Vec3& X) {
  const double s = 1.08 * X.x();
  return Vec3(kCylR * std::sin(s / kCylR), 0.97 * X.y(), kCylR * (1.0 - std::cos(s / kCylR)));
}
ExactStrain cylinder_exact(const Vec3&) { return {1.08, 0.97}; }

// Dome: the blank's polar radius r maps to the polar angle phi = a r on a sphere
// R = 80 mm. Meridional stretch R a, circumferential R sin(a r) / r.
constexpr double kDomeR = 80.0, kDomeA = 1.1 / 80.0;
Vec3 dome_map(const Vec3& X) {
  const double r = std::hypot(X.x(), X.y());
  const double phi = kDomeA * r;
  if (r < 1e-12) return Vec3(0, 0, kDomeR);
  const double s = kDomeR * std::sin(phi) / r;
  return Vec3(s * X.x(), s * X.y(), kDomeR * std::cos(phi));
}
ExactStrain dome_exact(const Vec3& X) {
  const double r = std::hypot(X.x(), X.y());
  const double lm = kDomeR * kDomeA;
  const double lc = r < 1e-12 ? lm : kDomeR * std::sin(kDomeA * r) / r;
  return {std::max(lm, lc), std::min(lm, lc)};
}

// Wavy 3-D map: in-plane stretch varying across the sheet plus an out-of-plane wave.
// Exact stretches from the analytic deformation gradient.
Vec3 wavy_map(const Vec3& X) {
  const double x = X.x(), y = X.y();
  return Vec3(x + 2.0 * std::sin(x / 25.0) + 0.001 * x * y, y + 1.5 * std::sin(y / 20.0 + 0.5),
              6.0 * std::sin(x / 18.0) * std::cos(y / 22.0));
}
ExactStrain wavy_exact(const Vec3& X) {
  const double x = X.x(), y = X.y();
  Mat32 g;
  g << 1.0 + (2.0 / 25.0) * std::cos(x / 25.0) + 0.001 * y, 0.001 * x,  //
      0.0, 1.0 + (1.5 / 20.0) * std::cos(y / 20.0 + 0.5),               //
      (6.0 / 18.0) * std::cos(x / 18.0) * std::cos(y / 22.0), -(6.0 / 22.0) * std::sin(x / 18.0) * std::sin(y / 22.0);
  const Mat2 C = g.transpose() * g;
  const double tr = C.trace(), det = C.determinant();
  const double d = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
  return {std::sqrt(tr / 2.0 + d), std::sqrt(tr / 2.0 - d)};
}

// Pin-jointed net (fibres 0 and 90 inextensible): x = f(X) + g(Y) with unit-speed
// curves; the 90-degree family turns by psi(Y) = 0.6 (Y + 50) / 100 rad, giving
// a trellis shear angle psi and fibre stretch 1 everywhere.
double trellis_psi(double y) { return 0.6 * (y + 50.0) / 100.0; }
Vec3 trellis_map(const Vec3& X) {
  // g(Y) = integral from -50 of (sin psi, cos psi) dY, psi linear in Y.
  const double k = 0.6 / 100.0, y0 = -50.0;
  const double gx = (-std::cos(trellis_psi(X.y())) + std::cos(trellis_psi(y0))) / k;
  const double gy = (std::sin(trellis_psi(X.y())) - std::sin(trellis_psi(y0))) / k;
  return Vec3(X.x() + gx, y0 + gy, 0.0);
}
ExactStrain trellis_exact(const Vec3& X) {
  const double psi = trellis_psi(X.y());
  // F = [e1, (sin psi, cos psi)]; C = [[1, sin psi], [sin psi, 1]] -> 1 +- sin psi.
  return {std::sqrt(1.0 + std::sin(psi)), std::sqrt(1.0 - std::sin(psi)), psi * 180.0 / kPi};
}

const std::vector<SyntheticCase>& cases() {
  static const std::vector<SyntheticCase> all = {
      {"rigid", "rigid rotation (0.7 rad about (1,2,3)) and translation: zero strain", rigid_map, rigid_exact},
      {"stretch", "homogeneous biaxial stretch 1.2 x 0.9, then rotated", stretch_map, stretch_exact},
      {"shear", "simple shear x = X + 0.3 Y", shear_map, shear_exact},
      {"cylinder", "stretch 1.08 x 0.97, then bent isometrically onto a cylinder R = 60 mm", cylinder_map,
       cylinder_exact},
      {"dome", "blank mapped onto a sphere R = 80 mm, polar angle = 1.1 r / R (meridional stretch 1.1)", dome_map,
       dome_exact},
      {"wavy", "in-plane stretch varying across the sheet plus an out-of-plane wave (amplitude 6 mm)", wavy_map,
       wavy_exact},
      {"trellis", "pin-jointed net of 0/90 fibres: trellis shear growing from 0 to 34.4 degrees across Y", trellis_map,
       trellis_exact},
  };
  return all;
}
}  // namespace

const SyntheticCase& synthetic_case(const std::string& name) {
  for (const auto& c : cases())
    if (c.name == name) return c;
  std::string known;
  for (const auto& c : cases()) known += (known.empty() ? "" : ", ") + c.name;
  throw UsageError("unknown synthetic case '" + name + "' (known: " + known + ")");
}

std::vector<std::string> synthetic_case_names() {
  std::vector<std::string> out;
  for (const auto& c : cases()) out.push_back(c.name);
  return out;
}

GridData make_synthetic_grid(const SyntheticCase& c, const SyntheticGridOptions& o, std::vector<ExactStrain>* exact) {
  GridData g;
  g.sources = {"synthetic:" + c.name};
  const Index n = static_cast<Index>(o.n) * o.n;
  g.ids.resize(n);
  g.undeformed.resize(n, 3);
  g.deformed.resize(n, 3);
  g.has_ij = true;
  g.i.resize(n);
  g.j.resize(n);
  g.where.resize(n);
  if (exact) exact->resize(n);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double half = 0.5 * (o.n - 1) * o.spacing;
  for (int j = 0; j < o.n; ++j)
    for (int i = 0; i < o.n; ++i) {
      const Index p = static_cast<Index>(j) * o.n + i;
      const Vec3 X(i * o.spacing - half, j * o.spacing - half, 0.0);
      g.ids[p] = "P" + std::to_string(j) + "_" + std::to_string(i);
      g.i[p] = j;
      g.j[p] = i;
      g.where[p] = g.sources[0];
      Vec3 Xn = X, xn = c.map(X);
      if (o.noise > 0) {
        for (int k = 0; k < 3; ++k) {
          Xn[k] += o.noise * noise(rng);
          xn[k] += o.noise * noise(rng);
        }
      }
      g.undeformed.row(p) = Xn.transpose();
      g.deformed.row(p) = xn.transpose();
      if (o.missing_deformed > 0 && uni(rng) < o.missing_deformed)
        g.deformed.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
      if (exact) (*exact)[p] = c.exact(X);
    }
  // Outliers: marks digitised 2 mm off in the deformed state (deterministic picks).
  for (int k = 0; k < o.outliers; ++k) {
    const Index p = (static_cast<Index>(k) * 7919 + n / 3) % n;
    if (g.deformed.row(p).allFinite()) g.deformed(p, 2) += 2.0;
  }
  if (o.round) {
    // Keep the marks whose nominal position lies in the inscribed circle.
    Index kept = 0;
    for (Index p = 0; p < n; ++p) {
      const double x = g.j[p] * o.spacing - half, y = g.i[p] * o.spacing - half;
      if (std::hypot(x, y) > half * (1.0 + 1e-9)) continue;
      g.ids[kept] = g.ids[p];
      g.i[kept] = g.i[p];
      g.j[kept] = g.j[p];
      g.where[kept] = g.where[p];
      g.undeformed.row(kept) = g.undeformed.row(p);
      g.deformed.row(kept) = g.deformed.row(p);
      if (exact) (*exact)[kept] = (*exact)[p];
      ++kept;
    }
    g.ids.resize(kept);
    g.i.resize(kept);
    g.j.resize(kept);
    g.where.resize(kept);
    g.undeformed.conservativeResize(kept, 3);
    g.deformed.conservativeResize(kept, 3);
    if (exact) exact->resize(kept);
  }
  return g;
}

}  // namespace sf::gsa
