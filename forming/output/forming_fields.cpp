#include "forming/output/forming_fields.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "forming/output/sampling.hpp"

namespace sf::forming {
namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

// Signed angle (degrees) from u to v about the unit axis n, both projected onto the plane
// normal to n; 0 when either projection vanishes.
double signed_angle(const Vec3& u, const Vec3& v, const Vec3& n) {
  const Vec3 up = u - u.dot(n) * n, vp = v - v.dot(n) * n;
  if (up.norm() == 0.0 || vp.norm() == 0.0) return 0.0;
  return std::atan2(up.cross(vp).dot(n), up.dot(vp)) * kDeg;
}

double wrap180(double a) {
  while (a > 180.0) a -= 360.0;
  while (a <= -180.0) a += 360.0;
  return a;
}

// The mid-surface parameters (mean of the bottom and top layer) of a ply's parameter field.
MatX mid_surface(const PlyMesh& ply, const MatX& params) {
  const Index n = 4 * ply.n_surface_nodes();
  return 0.5 * (params.topRows(n) + params.bottomRows(n));
}

// Points bucketed in a uniform grid of cell size `cell` (3-D), for radius queries.
class PointBuckets {
 public:
  PointBuckets(const std::vector<Vec3>& p, double cell) : p_(p), cell_(cell) {
    for (std::size_t i = 0; i < p.size(); ++i) map_[key(cell_of(p[i]))].push_back(static_cast<int>(i));
  }
  template <class F>
  void within(const Vec3& q, double r, F&& visit) const {
    const Eigen::Vector3i lo = cell_of(q - Vec3::Constant(r)), hi = cell_of(q + Vec3::Constant(r));
    for (int a = lo[0]; a <= hi[0]; ++a)
      for (int b = lo[1]; b <= hi[1]; ++b)
        for (int c = lo[2]; c <= hi[2]; ++c) {
          const auto it = map_.find(key({a, b, c}));
          if (it == map_.end()) continue;
          for (int j : it->second) {
            const double d = (p_[static_cast<std::size_t>(j)] - q).norm();
            if (d <= r) visit(j, d);
          }
        }
  }

 private:
  Eigen::Vector3i cell_of(const Vec3& q) const {
    return {static_cast<int>(std::floor(q[0] / cell_)), static_cast<int>(std::floor(q[1] / cell_)),
            static_cast<int>(std::floor(q[2] / cell_))};
  }
  static std::int64_t key(const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c[0] + (1 << 20)) << 42) ^ (static_cast<std::int64_t>(c[1] + (1 << 20)) << 21) ^
           static_cast<std::int64_t>(c[2] + (1 << 20));
  }
  const std::vector<Vec3>& p_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<int>> map_;
};

}  // namespace

WrinkleResult wrinkle_indicator(const std::vector<Vec3>& X, const std::vector<Vec3>& x,
                                const std::vector<Vec3>& normals, double radius, double spacing) {
  WrinkleResult out;
  out.radius = radius;
  const std::size_t n = X.size();
  out.deviation.assign(n, kNoValue);
  if (n == 0 || !(radius > 0.0) || !(spacing > 0.0)) return out;
  const PointBuckets buckets(X, radius);
  const double sigma = radius;
  std::vector<Vec3> e1(n), e2(n), nn(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Weighted principal plane of the neighbours' current positions.
    std::vector<std::pair<int, double>> nb;
    buckets.within(X[i], radius, [&](int j, double d) { nb.emplace_back(j, std::exp(-(d / sigma) * (d / sigma))); });
    if (nb.size() < 10) continue;
    Vec3 c = Vec3::Zero();
    double ws = 0.0;
    for (const auto& [j, w] : nb) {
      c += w * x[static_cast<std::size_t>(j)];
      ws += w;
    }
    c /= ws;
    Mat3 cov = Mat3::Zero();
    for (const auto& [j, w] : nb) {
      const Vec3 d = x[static_cast<std::size_t>(j)] - c;
      cov += w * d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
    Vec3 nrm = eig.eigenvectors().col(0);
    if (nrm.dot(normals[i]) < 0.0) nrm = -nrm;
    const Vec3 u = eig.eigenvectors().col(2), v = nrm.cross(u);
    // h = c0 + c1 u + c2 v + c3 u^2 + c4 u v + c5 v^2 about x_i.
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& [j, w] : nb) {
      const Vec3 d = x[static_cast<std::size_t>(j)] - x[i];
      const double a = d.dot(u), b = d.dot(v), h = d.dot(nrm);
      Eigen::Matrix<double, 6, 1> phi;
      phi << 1.0, a, b, a * a, a * b, b * b;
      A += w * phi * phi.transpose();
      rhs += w * h * phi;
    }
    const Eigen::Matrix<double, 6, 1> coef = A.ldlt().solve(rhs);
    if (!coef.allFinite()) continue;
    out.deviation[i] = -coef[0];
    e1[i] = u;
    e2[i] = v;
    nn[i] = nrm;
  }
  // Gradient of d over the nearest samples (least-squares plane in the local frame).
  double sum_d2 = 0.0, sum_g2 = 0.0;
  std::size_t count = 0;
  const double rg = 1.6 * spacing;
  const PointBuckets near(X, rg);
  for (std::size_t i = 0; i < n; ++i) {
    const double di = out.deviation[i];
    if (!std::isfinite(di)) continue;
    out.amplitude = std::max(out.amplitude, std::abs(di));
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    int m = 0;
    near.within(X[i], rg, [&](int j, double) {
      const double dj = out.deviation[static_cast<std::size_t>(j)];
      if (static_cast<std::size_t>(j) == i || !std::isfinite(dj)) return;
      const Vec3 d = x[static_cast<std::size_t>(j)] - x[i];
      const Eigen::Vector2d s(d.dot(e1[i]), d.dot(e2[i]));
      A += s * s.transpose();
      rhs += (dj - di) * s;
      ++m;
    });
    sum_d2 += di * di;
    ++count;
    if (m >= 3 && std::abs(A.determinant()) > 1e-12 * A.trace() * A.trace())
      sum_g2 += A.ldlt().solve(rhs).squaredNorm();
  }
  if (count == 0) return out;
  out.rms = std::sqrt(sum_d2 / static_cast<double>(count));
  if (out.rms > 1e-9 * radius && sum_g2 > 0.0)
    out.wavelength = 2.0 * 3.14159265358979323846 * std::sqrt(sum_d2 / sum_g2);
  return out;
}

FormingFields::FormingFields(const Model& model, const VecX& x) : model_(model) {
  const int nb = model.n_bodies();
  for (int b = 0; b < nb; ++b) {
    const PlyMesh& ply = model.ply(b);
    current_.push_back(PlyMesh::unflatten(x.segment(model.offset(b), ply.n_dofs())));
    mid_.emplace_back(ply.surface(), mid_surface(ply, current_.back()));
    reference_mid_.emplace_back(ply.surface(), mid_surface(ply, ply.reference()));
    fibrous_.push_back(model.material(b).fibre_direction().norm() > 0.0);
    double h = 0.0;
    Vec3 N0 = Vec3::UnitZ();
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickParams Xe = ply.element_parameters(e, ply.reference());
      const Vec3 o = sample_brick(Xe, Xe, Vec3(0, 0, 0.5)).X;
      h = std::max({h, (sample_brick(Xe, Xe, Vec3(1, 0, 0.5)).X - o).norm(),
                    (sample_brick(Xe, Xe, Vec3(0, 1, 0.5)).X - o).norm()});
      if (e == 0)
        N0 = (sample_brick(Xe, Xe, Vec3(0.5, 0.5, 1)).X - sample_brick(Xe, Xe, Vec3(0.5, 0.5, 0)).X).normalized();
    }
    element_size_.push_back(h);
    normal0_.push_back(N0);
  }
  // Partners: nearest fibre-reinforced ply with non-parallel fibres and overlapping plan.
  std::vector<double> level(static_cast<std::size_t>(nb));
  std::vector<Eigen::AlignedBox3d> box(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) {
    const MatX mid = mid_surface(model.ply(b), model.ply(b).reference());
    Vec3 c = Vec3::Zero();
    const Index ns = model.ply(b).n_surface_nodes();
    for (Index s = 0; s < ns; ++s) {
      const Vec3 p = mid.row(4 * s).transpose();
      c += p;
      box[static_cast<std::size_t>(b)].extend(p);
    }
    level[static_cast<std::size_t>(b)] = (c / static_cast<double>(std::max<Index>(ns, 1))).dot(normal0_[0]);
  }
  partner_.assign(static_cast<std::size_t>(nb), -1);
  for (int b = 0; b < nb; ++b) {
    if (!fibrous_[static_cast<std::size_t>(b)]) continue;
    double best = 1e300;
    for (int o = 0; o < nb; ++o) {
      if (o == b || !fibrous_[static_cast<std::size_t>(o)]) continue;
      const Vec3 a = model.ply(b).fibre_direction(), ao = model.ply(o).fibre_direction();
      if (a.cross(ao).norm() < std::sin(5.0 / kDeg)) continue;
      Eigen::AlignedBox3d pb = box[static_cast<std::size_t>(b)], po = box[static_cast<std::size_t>(o)];
      const Vec3 n = normal0_[0];
      // Plan overlap: the boxes overlap once the normal direction is flattened.
      pb.min() -= pb.min().dot(n) * n.cwiseAbs();
      pb.max() -= pb.max().dot(n) * n.cwiseAbs();
      po.min() -= po.min().dot(n) * n.cwiseAbs();
      po.max() -= po.max().dot(n) * n.cwiseAbs();
      if (!pb.intersects(po)) continue;
      const double d = std::abs(level[static_cast<std::size_t>(o)] - level[static_cast<std::size_t>(b)]);
      if (d < best - 1e-9) {
        best = d;
        partner_[static_cast<std::size_t>(b)] = o;
      }
    }
  }
}

PlyPointFields FormingFields::local(int body, Index element, const Vec3& xi) const {
  const PlyMesh& ply = model_.ply(body);
  const BrickParams Xe = ply.element_parameters(element, ply.reference());
  const BrickParams xe = ply.element_parameters(element, current_[static_cast<std::size_t>(body)]);
  const BrickPoint s = sample_brick(Xe, xe, xi);
  PlyPointFields out;
  out.X = s.X;
  out.x = s.x;
  out.F = s.F;
  const Vec3 N0 = normal0_[static_cast<std::size_t>(body)];
  const Vec3 a0 = ply.fibre_direction();
  const Vec3 fa = s.F * a0;
  out.fibre_stretch = fa.norm();
  out.fibre = fa.norm() > 0.0 ? Vec3(fa / fa.norm()) : Vec3::Zero();
  const Vec3 m = s.F.inverse().transpose() * N0;
  out.normal = m.normalized();
  out.thickness = ply.thickness() / m.norm();
  out.fibre_angle_change_deg = signed_angle(a0, out.fibre, N0);
  const Vec3 fb = s.F * N0.cross(a0);
  const double c = fa.dot(fb) / (fa.norm() * fb.norm());
  out.ply_shear_deg = 90.0 - std::acos(std::clamp(c, -1.0, 1.0)) * kDeg;
  return out;
}

PlyPointFields FormingFields::at(int body, Index element, const Vec3& xi) const {
  PlyPointFields out = local(body, element, xi);
  const int p = partner(body);
  if (p < 0) return out;
  const mesh::Projection pr = mid_[static_cast<std::size_t>(p)].project(out.x);
  const double reach = 2.0 * (model_.ply(body).thickness() + model_.ply(p).thickness());
  if (pr.status != mesh::Projection::Status::kConverged || pr.distance > reach) return out;
  const PlyPointFields q = local(p, pr.element, Vec3(pr.xi[0], pr.xi[1], 0.5));
  const double theta0 =
      signed_angle(model_.ply(body).fibre_direction(), model_.ply(p).fibre_direction(), reference_normal(body));
  const double theta = signed_angle(out.fibre, q.fibre, out.normal);
  out.trellis_shear_deg = (theta0 < 0.0 ? -1.0 : 1.0) * wrap180(theta0 - theta);
  return out;
}

bool FormingFields::locate_reference(int body, const Vec3& X, Index& element, Vec2& xi) const {
  const mesh::Projection pr = reference_mid_[static_cast<std::size_t>(body)].project(X);
  if (!pr.ok()) return false;
  const Vec3 n = reference_normal(body);
  const Vec3 d = X - pr.point;
  if ((d - d.dot(n) * n).norm() > 1e-6 * std::max(1.0, element_size(body))) return false;
  element = pr.element;
  xi = pr.xi;
  return true;
}

WrinkleResult FormingFields::wrinkles(int body, int n, double radius) const {
  const PlyMesh& ply = model_.ply(body);
  std::vector<Vec3> X, x, normals;
  for (Index e = 0; e < ply.n_elements(); ++e)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const PlyPointFields f = local(body, e, Vec3((i + 0.5) / n, (j + 0.5) / n, 0.5));
        X.push_back(f.X);
        x.push_back(f.x);
        normals.push_back(f.normal);
      }
  const double h = element_size(body);
  return wrinkle_indicator(X, x, normals, radius > 0.0 ? radius : 4.0 * h, h / n);
}

}  // namespace sf::forming
