#include "forming/contact/tool_shape.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

constexpr int kAround = 48;  // tessellation segments around a shape of revolution
constexpr int kFilletSegments = 8;

void require_positive(double v, const std::string& what) {
  if (std::isfinite(v) && v > 0.0) return;
  std::ostringstream os;
  os.precision(10);
  os << what << ": expected a positive length (mm), found " << v;
  throw InputError(os.str());
}

void require_finite(const Vec3& v, const std::string& what) {
  if (v.allFinite()) return;
  throw InputError(what + ": expected finite coordinates (mm)");
}

Vec3 unit(const Vec3& v, const std::string& what) {
  if (!v.allFinite() || !(v.norm() > 0.0)) throw InputError(what + ": expected a non-zero direction");
  return v.normalized();
}

// Two unit vectors completing `a` (unit) to a right-handed frame (t1, t2, a).
std::pair<Vec3, Vec3> frame(const Vec3& a) {
  const Vec3 helper = std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = (helper - a * a.dot(helper)).normalized();
  return {t1, a.cross(t1)};
}

// A profile coordinate: value, gradient (unit) and Hessian in x.
struct Coordinate {
  double value = 0.0;
  Vec3 gradient = Vec3::Zero();
  Mat3 hessian = Mat3::Zero();
};

// Distance from an axis through `p` along unit `a`: rho, its gradient e_rho and Hessian
// (I - a a^T - e e^T)/rho. On the axis itself e_rho is any direction across it and the
// Hessian is left zero (such points lie deep inside or far from every shape here).
Coordinate radial(const Vec3& x, const Vec3& p, const Vec3& a) {
  const Vec3 d = x - p;
  const Vec3 perp = d - a * a.dot(d);
  Coordinate c;
  c.value = perp.norm();
  if (c.value > 1e-300) {
    c.gradient = perp / c.value;
    c.hessian = (Mat3::Identity() - a * a.transpose() - c.gradient * c.gradient.transpose()) / c.value;
  } else {
    c.gradient = frame(a).first;
  }
  return c;
}

Coordinate negated(Coordinate c, double shift) {
  c.value = shift - c.value;
  c.gradient = -c.gradient;
  c.hessian = -c.hessian;
  return c;
}

// phi = sd(core) - r for a core {u <= 0, w <= 0} whose corner is rounded by r (the
// Minkowski sum of the core with a disk of radius r); u and w have orthonormal gradients.
ToolPoint rounded_corner(const Coordinate& u, const Coordinate& w, double r) {
  ToolPoint t;
  if (u.value > 0.0 && w.value > 0.0) {
    const double sd = std::hypot(u.value, w.value);
    const Vec3 n = (u.value * u.gradient + w.value * w.gradient) / sd;
    t.gap = sd - r;
    t.normal = n;
    t.normal_gradient = (u.gradient * u.gradient.transpose() + u.value * u.hessian +
                         w.gradient * w.gradient.transpose() + w.value * w.hessian - n * n.transpose()) /
                        sd;
  } else {
    const Coordinate& c = (w.value <= 0.0 && (u.value > 0.0 || u.value > w.value)) ? u : w;
    t.gap = c.value - r;
    t.normal = c.gradient;
    t.normal_gradient = c.hessian;
  }
  t.gap_gradient = t.normal;
  return t;
}

// Corners of the box [lo, hi].
std::array<Vec3, 8> corners(const Vec3& lo, const Vec3& hi) {
  std::array<Vec3, 8> c;
  for (int k = 0; k < 8; ++k) c[k] = Vec3(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  return c;
}

// Range of (x - p) . a over the box corners.
std::pair<double, double> extent_along(const Vec3& lo, const Vec3& hi, const Vec3& p, const Vec3& a) {
  double mn = 1e300, mx = -1e300;
  for (const Vec3& c : corners(lo, hi)) {
    const double s = (c - p).dot(a);
    mn = std::min(mn, s);
    mx = std::max(mx, s);
  }
  return {mn, mx};
}

// A surface of revolution about axis (p, a) from a profile polyline of (rho, s) points
// (s along a). A profile point on the axis (rho = 0) is one point, fanned to its ring.
ToolTessellation revolve(const Vec3& p, const Vec3& a, const std::vector<std::pair<double, double>>& profile) {
  const auto [t1, t2] = frame(a);
  double scale = 0.0;
  for (const auto& q : profile) scale = std::max({scale, std::abs(q.first), std::abs(q.second)});
  ToolTessellation out;
  std::vector<Vec3> points;
  std::vector<std::vector<Index>> rings;  // point ids of each profile point (one on the axis)
  for (const auto& [rho, s] : profile) {
    std::vector<Index> ring;
    const int n = std::abs(rho) <= 1e-12 * scale ? 1 : kAround;
    for (int k = 0; k < n; ++k) {
      const double phi = 2.0 * kPi * k / kAround;
      ring.push_back(static_cast<Index>(points.size()));
      points.push_back(p + s * a + (n == 1 ? 0.0 : rho) * (std::cos(phi) * t1 + std::sin(phi) * t2));
    }
    rings.push_back(std::move(ring));
  }
  for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
    const std::vector<Index>& r0 = rings[i];
    const std::vector<Index>& r1 = rings[i + 1];
    for (int k = 0; k < kAround; ++k) {
      const auto at = [](const std::vector<Index>& r, int j) {
        return r[r.size() == 1 ? 0 : std::size_t(j % kAround)];
      };
      const Index a0 = at(r0, k), a1 = at(r0, k + 1), b0 = at(r1, k), b1 = at(r1, k + 1);
      if (a0 != a1) out.triangles.push_back({a0, a1, b1});
      if (b0 != b1) out.triangles.push_back({a0, b1, b0});
    }
  }
  out.points.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) out.points.row(static_cast<Index>(i)) = points[i].transpose();
  return out;
}

// The profile of a quarter circle of radius r about (rho0, s0) from angle th0 to th1.
void arc(std::vector<std::pair<double, double>>& profile, double rho0, double s0, double r, double th0, double th1) {
  for (int i = 0; i <= kFilletSegments; ++i) {
    const double th = th0 + (th1 - th0) * i / kFilletSegments;
    profile.emplace_back(rho0 + r * std::cos(th), s0 + r * std::sin(th));
  }
}

class Plane final : public ToolShape {
 public:
  Plane(const Vec3& point, const Vec3& normal) : p_(point), n_(unit(normal, "plane normal")) {
    require_finite(point, "plane point");
  }
  std::string kind() const override { return "plane"; }
  ToolPoint evaluate(const Vec3& x) const override {
    ToolPoint t;
    t.gap = (x - p_).dot(n_);
    t.normal = t.gap_gradient = n_;
    return t;
  }
  ToolTessellation tessellate(const Vec3& lo, const Vec3& hi) const override {
    const auto [t1, t2] = frame(n_);
    const auto [a0, a1] = extent_along(lo, hi, p_, t1);
    const auto [b0, b1] = extent_along(lo, hi, p_, t2);
    ToolTessellation out;
    out.points.resize(4, 3);
    out.points.row(0) = (p_ + a0 * t1 + b0 * t2).transpose();
    out.points.row(1) = (p_ + a1 * t1 + b0 * t2).transpose();
    out.points.row(2) = (p_ + a1 * t1 + b1 * t2).transpose();
    out.points.row(3) = (p_ + a0 * t1 + b1 * t2).transpose();
    out.triangles = {{0, 1, 2}, {0, 2, 3}};
    return out;
  }

 private:
  Vec3 p_, n_;
};

class Sphere final : public ToolShape {
 public:
  Sphere(const Vec3& centre, double radius) : c_(centre), r_(radius) {
    require_finite(centre, "sphere centre");
    require_positive(radius, "sphere radius");
  }
  std::string kind() const override { return "sphere"; }
  ToolPoint evaluate(const Vec3& x) const override {
    const Vec3 d = x - c_;
    const double l = d.norm();
    ToolPoint t;
    if (!(l > 1e-300)) {  // the centre: no direction
      t.gap = -r_;
      t.in_front = false;
      return t;
    }
    t.gap = l - r_;
    t.normal = t.gap_gradient = d / l;
    t.normal_gradient = (Mat3::Identity() - t.normal * t.normal.transpose()) / l;
    return t;
  }
  ToolTessellation tessellate(const Vec3&, const Vec3&) const override {
    std::vector<std::pair<double, double>> profile;
    const int n = 2 * kFilletSegments;
    for (int i = 0; i <= n; ++i) {
      const double th = -0.5 * kPi + kPi * i / n;
      profile.emplace_back(r_ * std::cos(th), r_ * std::sin(th));
    }
    return revolve(c_, Vec3::UnitZ(), profile);
  }

 private:
  Vec3 c_;
  double r_;
};

class Cylinder final : public ToolShape {
 public:
  Cylinder(const Vec3& point, const Vec3& axis, double radius)
      : p_(point), a_(unit(axis, "cylinder axis")), r_(radius) {
    require_finite(point, "cylinder point");
    require_positive(radius, "cylinder radius");
  }
  std::string kind() const override { return "cylinder"; }
  ToolPoint evaluate(const Vec3& x) const override {
    const Coordinate rho = radial(x, p_, a_);
    ToolPoint t;
    if (!(rho.value > 1e-300)) {
      t.gap = -r_;
      t.in_front = false;
      return t;
    }
    t.gap = rho.value - r_;
    t.normal = t.gap_gradient = rho.gradient;
    t.normal_gradient = rho.hessian;
    return t;
  }
  ToolTessellation tessellate(const Vec3& lo, const Vec3& hi) const override {
    const auto [s0, s1] = extent_along(lo, hi, p_, a_);
    return revolve(p_, a_, {{r_, s0}, {r_, s1}});
  }

 private:
  Vec3 p_, a_;
  double r_;
};

class Punch final : public ToolShape {
 public:
  Punch(const Vec3& tip, const Vec3& axis, double radius, double fillet)
      : tip_(tip), a_(unit(axis, "punch axis")), r_(radius), f_(fillet) {
    require_finite(tip, "punch tip");
    require_positive(radius, "punch radius");
    require_positive(fillet, "punch fillet");
    if (fillet > radius) {
      std::ostringstream os;
      os << "punch fillet: expected at most the radius " << radius << " mm, found " << fillet;
      throw InputError(os.str());
    }
  }
  std::string kind() const override { return "punch"; }
  ToolPoint evaluate(const Vec3& x) const override {
    // u = rho - (R - r) (beyond the side), w = r + (x - tip) . a (in front of the core).
    Coordinate u = radial(x, tip_, a_);
    u.value -= r_ - f_;
    Coordinate w;
    w.value = f_ + (x - tip_).dot(a_);
    w.gradient = a_;
    return rounded_corner(u, w, f_);
  }
  ToolTessellation tessellate(const Vec3& lo, const Vec3& hi) const override {
    const auto [s0, s1] = extent_along(lo, hi, tip_, -a_);
    const double length = std::max({2.0 * r_, s1, -s0});
    // Profile in (rho, s) with s along -a (into the punch): end face, fillet, side.
    std::vector<std::pair<double, double>> profile = {{0.0, 0.0}};
    arc(profile, r_ - f_, f_, f_, -0.5 * kPi, 0.0);
    profile.emplace_back(r_, length);
    return revolve(tip_, -a_, profile);
  }

 private:
  Vec3 tip_, a_;
  double r_, f_;
};

class Die final : public ToolShape {
 public:
  Die(const Vec3& centre, const Vec3& normal, const DieOpening& opening, double edge_radius)
      : c_(centre), n_(unit(normal, "die normal")), o_(opening), r_(edge_radius) {
    require_finite(centre, "die centre");
    require_positive(edge_radius, "die edge_radius");
    if (o_.slot) {
      require_positive(o_.half_width, "die slot half_width");
      const Vec3 along = o_.along - n_ * n_.dot(o_.along);
      if (!(along.norm() > 1e-6 * std::max(o_.along.norm(), 1e-300)))
        throw InputError("die slot along: expected a direction in the die's top face (not along its normal)");
      o_.along = along.normalized();
      lateral_ = n_.cross(o_.along);
    } else {
      require_positive(o_.radius, "die opening radius");
    }
  }
  std::string kind() const override { return "die"; }
  ToolPoint evaluate(const Vec3& x) const override {
    // rho: distance from the opening's axis (circle) or mid-plane (slot);
    // u = (R_o + r) - rho (into the opening beyond the core), w = h + r (above the core).
    Coordinate rho;
    if (o_.slot) {
      const double s = (x - c_).dot(lateral_);
      rho.value = std::abs(s);
      rho.gradient = s >= 0.0 ? lateral_ : Vec3(-lateral_);
    } else {
      rho = radial(x, c_, n_);
    }
    const double opening = o_.slot ? o_.half_width : o_.radius;
    const Coordinate u = negated(rho, opening + r_);
    Coordinate w;
    w.value = (x - c_).dot(n_) + r_;
    w.gradient = n_;
    return rounded_corner(u, w, r_);
  }
  ToolTessellation tessellate(const Vec3& lo, const Vec3& hi) const override {
    const double opening = o_.slot ? o_.half_width : o_.radius;
    double reach = 0.0;  // how far the box reaches from the centre
    for (const Vec3& c : corners(lo, hi)) reach = std::max(reach, (c - c_).norm());
    reach = std::max(reach, 2.0 * (opening + r_));
    const double depth = std::max(reach - opening, 2.0 * r_);
    // Profile (rho, s) with s along n: top face from the outside in, fillet, wall down.
    std::vector<std::pair<double, double>> profile = {{reach, 0.0}};
    arc(profile, opening + r_, -r_, r_, 0.5 * kPi, kPi);
    profile.emplace_back(opening, -depth);
    if (!o_.slot) return revolve(c_, n_, profile);
    // Slot: the profile extruded along the slot on both sides of the mid-plane.
    const auto [a0, a1] = extent_along(lo, hi, c_, o_.along);
    ToolTessellation out;
    const int m = static_cast<int>(profile.size());
    out.points.resize(4 * m, 3);
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < m; ++i)
        for (int e = 0; e < 2; ++e) {
          const double sign = side == 0 ? 1.0 : -1.0;
          const Vec3 q = c_ + sign * profile[static_cast<std::size_t>(i)].first * lateral_ +
                         profile[static_cast<std::size_t>(i)].second * n_ + (e == 0 ? a0 : a1) * o_.along;
          out.points.row(2 * (side * m + i) + e) = q.transpose();
        }
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i + 1 < m; ++i) {
        const Index p0 = 2 * (side * m + i), p1 = p0 + 1, q0 = p0 + 2, q1 = p0 + 3;
        out.triangles.push_back({p0, q0, q1});
        out.triangles.push_back({p0, q1, p1});
      }
    return out;
  }

 private:
  Vec3 c_, n_;
  DieOpening o_;
  double r_;
  Vec3 lateral_ = Vec3::UnitX();
};

class MeshTool final : public ToolShape {
 public:
  explicit MeshTool(mesh::TriangleSurface surface) : surface_(std::move(surface)) {}
  std::string kind() const override { return "mesh"; }
  bool symmetric() const override { return false; }
  ToolPoint evaluate(const Vec3& x) const override {
    const mesh::SurfaceClosestPoint c = surface_.closest(x);
    ToolPoint t;
    t.gap = c.gap;
    t.normal = c.normal;
    t.gap_gradient = c.gap_gradient;
    t.normal_gradient = c.normal_gradient;
    t.in_front = c.in_front;
    return t;
  }
  ToolTessellation tessellate(const Vec3&, const Vec3&) const override {
    return {surface_.vertices(), surface_.triangles()};
  }

 private:
  mesh::TriangleSurface surface_;
};

}  // namespace

std::shared_ptr<const ToolShape> make_plane(const Vec3& point, const Vec3& normal) {
  return std::make_shared<Plane>(point, normal);
}
std::shared_ptr<const ToolShape> make_sphere(const Vec3& centre, double radius) {
  return std::make_shared<Sphere>(centre, radius);
}
std::shared_ptr<const ToolShape> make_cylinder(const Vec3& point, const Vec3& axis, double radius) {
  return std::make_shared<Cylinder>(point, axis, radius);
}
std::shared_ptr<const ToolShape> make_punch(const Vec3& tip, const Vec3& axis, double radius, double fillet) {
  return std::make_shared<Punch>(tip, axis, radius, fillet);
}
std::shared_ptr<const ToolShape> make_die(const Vec3& centre, const Vec3& normal, const DieOpening& opening,
                                          double edge_radius) {
  return std::make_shared<Die>(centre, normal, opening, edge_radius);
}
std::shared_ptr<const ToolShape> make_mesh_tool(const io::TriangleMesh& mesh, double scale, const Vec3& offset) {
  if (!(std::isfinite(scale) && scale > 0.0)) {
    std::ostringstream os;
    os << "mesh tool scale: expected a positive factor, found " << scale;
    throw InputError(os.str());
  }
  require_finite(offset, "mesh tool offset");
  Points3 v = mesh.vertices * scale;
  v.rowwise() += offset.transpose();
  return std::make_shared<MeshTool>(mesh::TriangleSurface(std::move(v), mesh.triangles));
}

}  // namespace sf::forming
