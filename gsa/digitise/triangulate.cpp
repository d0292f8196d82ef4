#include "gsa/digitise/triangulate.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace sf::gsa::digitise {

namespace {

// Homogeneous linear triangulation in normalised coordinates.
bool linear(const Rig& rig, const std::vector<Observation>& obs, Vec3& X) {
  Eigen::MatrixXd A(2 * obs.size(), 4);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const Camera& c = rig.cameras[obs[k].camera];
    const Vec2 x = c.pixel_to_normalised(obs[k].pixel);
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = c.R;
    P.col(3) = c.t;
    A.row(2 * k) = x.x() * P.row(2) - P.row(0);
    A.row(2 * k + 1) = x.y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (!(std::abs(h(3)) > 1e-300)) return false;
  X = h.head<3>() / h(3);
  return X.allFinite();
}

double cost(const Rig& rig, const std::vector<Observation>& obs, const Vec3& X, std::vector<double>* res = nullptr) {
  double c = 0;
  if (res) res->clear();
  for (const Observation& o : obs) {
    const Camera& cam = rig.cameras[o.camera];
    if (!cam.in_front(X)) return std::numeric_limits<double>::infinity();
    const double r = (cam.project(X) - o.pixel).norm();
    c += r * r;
    if (res) res->push_back(r);
  }
  return c;
}

// Gauss-Newton with step halving on the pixel reprojection error.
void refine(const Rig& rig, const std::vector<Observation>& obs, Vec3& X, int max_iterations) {
  double c = cost(rig, obs, X);
  for (int it = 0; it < max_iterations && std::isfinite(c); ++it) {
    Mat3 JtJ = Mat3::Zero();
    Vec3 Jtr = Vec3::Zero();
    for (const Observation& o : obs) {
      Eigen::Matrix<double, 2, 3> J;
      const Vec2 r = rig.cameras[o.camera].project(X, &J) - o.pixel;
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Vec3 step = -JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) break;
    double f = 1.0, cn = cost(rig, obs, X + step);
    while (!(cn <= c) && f > 1e-4) {
      f *= 0.5;
      cn = cost(rig, obs, X + f * step);
    }
    if (!(cn <= c)) break;
    X += f * step;
    const bool small = f * step.norm() < 1e-12 * (1.0 + X.norm());
    c = cn;
    if (small) break;
  }
}

}  // namespace

TriangulatedPoint triangulate(const Rig& rig, const std::vector<Observation>& observations,
                              const TriangulationOptions& o) {
  TriangulatedPoint p;
  std::vector<Observation> obs = observations;
  while (true) {
    if (obs.size() < 2) {
      p.why = "seen in fewer than two views";
      return p;
    }
    Vec3 X;
    if (!linear(rig, obs, X)) {
      p.why = "the views' rays are parallel";
      return p;
    }
    refine(rig, obs, X, o.max_iterations);
    std::vector<double> res;
    const double c = cost(rig, obs, X, &res);
    if (!std::isfinite(c)) {
      p.why = "the point falls behind a camera";
      return p;
    }
    const double rms = std::sqrt(c / obs.size());
    const auto worst = std::max_element(res.begin(), res.end());
    if (obs.size() >= 3 && *worst > o.max_reprojection_px) {
      obs.erase(obs.begin() + (worst - res.begin()));
      continue;
    }
    p.X = X;
    p.rms_px = rms;
    p.used = obs;
    p.residual_px = res;
    if (rms > o.max_reprojection_px) {
      p.why = fmt::format("reprojection error {:.2f} px > {} px (views disagree)", rms, o.max_reprojection_px);
      return p;
    }
    p.ok = true;
    return p;
  }
}

namespace {

// The disc's outline projected through the camera, as a polygon.
std::vector<Vec2> disc_outline(const Camera& camera, const Vec3& centre, const Vec3& normal, double radius) {
  const Vec3 n = normal.normalized();
  const Vec3 a = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 b = n.cross(a);
  constexpr int kN = 96;
  std::vector<Vec2> poly(kN);
  for (int k = 0; k < kN; ++k) {
    const double t = 2 * kPi * k / kN;
    poly[k] = camera.project(centre + radius * (std::cos(t) * a + std::sin(t) * b));
  }
  return poly;
}

// Signed area and area centroid of a polygon (shoelace).
std::pair<double, Vec2> area_centroid(const std::vector<Vec2>& poly) {
  double A = 0;
  Vec2 C = Vec2::Zero();
  const Vec2 o = poly[0];  // relative coordinates for accuracy
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const Vec2 p = poly[k] - o, q = poly[(k + 1) % poly.size()] - o;
    const double cr = p.x() * q.y() - p.y() * q.x();
    A += cr;
    C += cr * (p + q);
  }
  A *= 0.5;
  return {A, o + C / (6.0 * A)};
}

}  // namespace

Vec2 disc_centroid_offset(const Camera& camera, const Vec3& centre, const Vec3& normal, double radius) {
  const auto poly = disc_outline(camera, centre, normal, radius);
  const auto [A, C] = area_centroid(poly);
  if (!(std::abs(A) > 0)) return Vec2::Zero();
  return C - camera.project(centre);
}

double disc_image_area(const Camera& camera, const Vec3& centre, const Vec3& normal, double radius) {
  return std::abs(area_centroid(disc_outline(camera, centre, normal, radius)).first);
}

}  // namespace sf::gsa::digitise
