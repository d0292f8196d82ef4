// Tests of the nearest-point projection (common/mesh/projection.hpp).

#include "common/mesh/projection.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "common/core/error.hpp"
#include "common/fe/surface_field.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kXiTol = 1e-10;    // xi recovered for points on the surface
constexpr double kDistTol = 1e-9;   // mm, distances of exactly known feet
constexpr double kOrthoTol = 1e-8;  // relative |r . x,i| / (|r| |x,i|) at a converged result

using Status = Projection::Status;

// Flat 40 x 30 mm rectangle in z = 0, 4 x 3 elements of 10 x 10 mm.
SurfaceMesh flat_mesh() { return make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 40.0, 30.0, 4, 3); }

// z = f(x, y), degree <= 3 in x and in y, so the bicubic Hermite mesh reproduces it exactly.
struct Height {
  static double f(double x, double y) {
    return 0.004 * (x - 20) * (x - 20) - 0.003 * (y - 15) * (y - 15) + 0.0001 * x * y * y;
  }
  static double fx(double x, double y) { return 0.008 * (x - 20) + 0.0001 * y * y; }
  static double fy(double x, double y) { return -0.006 * (y - 15) + 0.0002 * x * y; }
  static double fxy(double, double y) { return 0.0002 * y; }
};

// The flat mesh lifted to z = Height::f(x, y): x, y stay linear in xi (scale factors 10 mm).
SurfaceMesh curved_mesh() {
  SurfaceMesh mesh = flat_mesh();
  for (Index node = 0; node < mesh.n_nodes(); ++node) {
    const Vec3 q = mesh.node_position(node);
    const double x = q.x(), y = q.y();
    mesh.geometry().row(SurfaceMesh::dof(node, kValue)) = Vec3(x, y, Height::f(x, y)).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD1)) = Vec3(1, 0, Height::fx(x, y)).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD2)) = Vec3(0, 1, Height::fy(x, y)).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD12)) = Vec3(0, 0, Height::fxy(x, y)).transpose();
  }
  return mesh;
}

// Half cylinder of radius r about the z axis (theta in [0, pi]), 20 mm tall, 6 x 2 elements.
SurfaceMesh half_cylinder_mesh(double r) {
  SurfaceMesh mesh = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), kPi * r, 20.0, 6, 2);
  for (Index node = 0; node < mesh.n_nodes(); ++node) {
    const Vec3 q = mesh.node_position(node);
    const double th = q.x() / r;
    mesh.geometry().row(SurfaceMesh::dof(node, kValue)) = Vec3(r * std::cos(th), r * std::sin(th), q.y()).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD1)) = Vec3(-std::sin(th), std::cos(th), 0).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD2)) = Vec3(0, 0, 1).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD12)) = Vec3::Zero().transpose();
  }
  return mesh;
}

// Spherical cap (a hemisphere of radius r about the origin, pole at (0, 0, r)) made
// from a disk mesh: disk radius rho -> polar angle pi/2 rho; collapsed elements at the pole.
SurfaceMesh dome_mesh(double r, int n_rings, int n_sectors) {
  SurfaceMesh mesh = make_disk_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0, n_rings, n_sectors);
  for (Index node = 0; node < mesh.n_nodes(); ++node) {
    const Vec3 q = mesh.node_position(node);
    const double phi = 0.5 * kPi * q.norm(), th = std::atan2(q.y(), q.x());
    const Vec3 x = r * Vec3(std::sin(phi) * std::cos(th), std::sin(phi) * std::sin(th), std::cos(phi));
    mesh.geometry().row(SurfaceMesh::dof(node, kValue)) = x.transpose();
    if (node == 0) continue;  // apex: value only changes; D1, D2 stay x, y (tangent plane)
    const Vec3 t1(-std::sin(th), std::cos(th), 0.0);
    const Vec3 t2(std::cos(phi) * std::cos(th), std::cos(phi) * std::sin(th), -std::sin(phi));
    mesh.geometry().row(SurfaceMesh::dof(node, kD1)) = t1.transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD2)) = t2.transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, kD12)) = (t1 * std::cos(phi) / (r * std::sin(phi))).transpose();
  }
  mesh.compute_arc_length_scale_factors();
  return mesh;
}

Vec3 unit_normal(const fe::SurfacePoint& s) { return s.dx.col(0).cross(s.dx.col(1)).normalized(); }

// At a converged interior result, p - x is orthogonal to x,1 and x,2.
void expect_residual_normal(const fe::SurfaceField& field, const Vec3& p, const Projection& r) {
  const auto s = field.evaluate3(r.element, r.xi, basis::kValues | basis::kFirst);
  const Vec3 res = p - s.x;
  EXPECT_NEAR((s.x - r.point).norm(), 0.0, 1e-12) << r.brief();
  EXPECT_NEAR(res.norm(), r.distance, 1e-12) << r.brief();
  for (int i = 0; i < 2; ++i) {
    const double scale = res.norm() * s.dx.col(i).norm() + 1e-12;
    EXPECT_LE(std::abs(res.dot(s.dx.col(i))) / scale, kOrthoTol)
        << "tangent " << i << " at " << r.brief() << " p=" << p.transpose();
  }
}

// Dense sample of the surface: (per_edge + 1)^2 points per element.
std::vector<Vec3> dense_sample(const fe::SurfaceField& field, int per_edge) {
  std::vector<Vec3> out;
  for (Index e = 0; e < field.mesh().n_elements(); ++e)
    for (int j = 0; j <= per_edge; ++j)
      for (int i = 0; i <= per_edge; ++i) {
        const Vec2 xi(static_cast<double>(i) / per_edge, static_cast<double>(j) / per_edge);
        out.push_back(field.evaluate3(e, xi, basis::kValues).x);
      }
  return out;
}

// Smallest distance from p to the sample (an upper bound of the distance to the surface).
double min_distance(const std::vector<Vec3>& sample, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& q : sample) best = std::min(best, (q - p).squaredNorm());
  return std::sqrt(best);
}

TEST(ProjectionTest, PointsOnFlatMeshRecoverElementAndXi) {
  const SurfaceMesh mesh = flat_mesh();
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uxi(0.01, 0.99);
  std::uniform_int_distribution<Index> uel(0, mesh.n_elements() - 1);
  for (int k = 0; k < 200; ++k) {
    const Index e = uel(rng);
    const Vec2 xi(uxi(rng), uxi(rng));
    const Vec3 p = field.evaluate3(e, xi, basis::kValues).x;
    const Projection r = projector.project(p);
    ASSERT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_EQ(r.element, e) << r.brief();
    EXPECT_NEAR(r.xi[0], xi[0], kXiTol) << r.brief();
    EXPECT_NEAR(r.xi[1], xi[1], kXiTol) << r.brief();
    EXPECT_LT(r.distance, kDistTol);
    EXPECT_LT((r.point - p).norm(), kDistTol);
  }
}

TEST(ProjectionTest, NormalOffsetRecoversFootAndDistance) {
  // A tilted, graded rectangle: the frame is not axis aligned, elements differ in size.
  const Vec3 a1 = Vec3(1, 1, 0).normalized();
  const Vec3 a2 = Vec3(-1, 1, 2).normalized();
  const SurfaceMesh mesh =
      make_rectangle_mesh(Vec3(5, -3, 2), a1, a2, 30.0, 20.0, 3, 2, {0.0, 6.0, 18.0, 30.0}, {0.0, 12.0, 20.0});
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> uxi(0.02, 0.98), uh(-2.0, 2.0);
  std::uniform_int_distribution<Index> uel(0, mesh.n_elements() - 1);
  for (int k = 0; k < 200; ++k) {
    const Index e = uel(rng);
    const Vec2 xi(uxi(rng), uxi(rng));
    const auto s = field.evaluate3(e, xi, basis::kValues | basis::kFirst);
    const double h = uh(rng);
    const Vec3 p = s.x + h * unit_normal(s);
    const Projection r = projector.project(p);
    ASSERT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_EQ(r.element, e);
    EXPECT_NEAR(r.xi[0], xi[0], 1e-9);
    EXPECT_NEAR(r.xi[1], xi[1], 1e-9);
    EXPECT_NEAR(r.distance, std::abs(h), kDistTol);
    EXPECT_LT((r.point - s.x).norm(), kDistTol) << r.brief() << " h=" << h;
  }
}

TEST(ProjectionTest, CurvedSurfaceResidualIsNormalAndMinimal) {
  const SurfaceMesh mesh = curved_mesh();
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  // Points on the surface: element and xi recovered, and the projector's own
  // evaluation agrees with SurfaceField and with the analytic height.
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> uxi(0.01, 0.99);
  std::uniform_int_distribution<Index> uel(0, mesh.n_elements() - 1);
  for (int k = 0; k < 100; ++k) {
    const Index e = uel(rng);
    const Vec2 xi(uxi(rng), uxi(rng));
    const Vec3 p = field.evaluate3(e, xi, basis::kValues).x;
    ASSERT_NEAR(p.z(), Height::f(p.x(), p.y()), 1e-12);
    const Projection r = projector.project(p);
    ASSERT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_EQ(r.element, e);
    EXPECT_NEAR(r.xi[0], xi[0], kXiTol);
    EXPECT_NEAR(r.xi[1], xi[1], kXiTol);
    EXPECT_LT(r.distance, kDistTol);
  }
  // Points off the surface: residual normal to the surface, foot on the analytic
  // surface, and no point of a dense sample is closer.
  std::uniform_real_distribution<double> ux(1.0, 39.0), uy(1.0, 29.0), uz(-3.0, 3.0);
  const std::vector<Vec3> sample = dense_sample(field, 40);
  int converged = 0;
  for (int k = 0; k < 60; ++k) {
    const double x = ux(rng), y = uy(rng);
    const Vec3 p(x, y, Height::f(x, y) + uz(rng));
    const Projection r = projector.project(p);
    ASSERT_TRUE(r.ok()) << r.brief();
    EXPECT_NEAR(r.point.z(), Height::f(r.point.x(), r.point.y()), 1e-10);
    if (r.status == Status::kConverged) {
      ++converged;
      expect_residual_normal(field, p, r);
      EXPECT_LE(r.iterations, 8) << "Newton should converge quadratically: " << r.brief();
    }
    EXPECT_LE(r.distance, min_distance(sample, p) + 1e-12) << r.brief();
  }
  EXPECT_GT(converged, 50);
}

TEST(ProjectionTest, CylinderResidualIsNormalAndMinimal) {
  // Points inside and outside a half cylinder; inside points far from the wall have
  // an indefinite Hessian along the arc (beyond the centre of curvature).
  const double radius = 10.0;
  const SurfaceMesh mesh = half_cylinder_mesh(radius);
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> ur(1.0, 16.0), uth(0.15, kPi - 0.15), uz(1.0, 19.0);
  const std::vector<Vec3> sample = dense_sample(field, 30);
  for (int k = 0; k < 60; ++k) {
    const double rr = ur(rng), th = uth(rng);
    const Vec3 p(rr * std::cos(th), rr * std::sin(th), uz(rng));
    const Projection r = projector.project(p);
    ASSERT_EQ(r.status, Status::kConverged) << r.brief() << " p=" << p.transpose();
    expect_residual_normal(field, p, r);
    EXPECT_NEAR(r.distance, std::abs(rr - radius), 2e-3 * radius);  // cubic arc vs. circle
    EXPECT_LE(r.distance, min_distance(sample, p) + 1e-12) << r.brief();
  }
  // Near the axis, started on the far side of the arc: there the Hessian is indefinite
  // (p lies beyond the centre of curvature of the start point) and the iteration must
  // fall back to Gauss-Newton, then walk over three elements.
  {
    const double th = 2.5;
    const Vec3 p(0.8 * std::cos(th), 0.8 * std::sin(th), 7.0);
    const Projection w = projector.refine(p, 0, Vec2(0.2, 0.5));
    ASSERT_EQ(w.status, Status::kConverged) << w.brief();
    expect_residual_normal(field, p, w);
    EXPECT_NEAR(std::atan2(w.point.y(), w.point.x()), th, 0.05) << w.brief();  // cubic arc
    EXPECT_LE(w.distance, min_distance(sample, p) + 1e-12) << w.brief();
    const Projection r = projector.project(p);
    EXPECT_EQ(r.element, w.element);
    EXPECT_NEAR(r.distance, w.distance, 1e-12);
  }
  // Below the axis, outside the arc: the nearest points are the straight free edges.
  const Vec3 p(0.5, -3.0, 10.0);
  const Projection r = projector.project(p);
  EXPECT_EQ(r.status, Status::kOnFreeEdge) << r.brief();
  EXPECT_NEAR(r.distance, Vec3(radius - 0.5, 3.0, 0.0).norm(), 1e-9);
  EXPECT_LE(r.distance, min_distance(sample, p) + 1e-12);
}

TEST(ProjectionTest, NearElementBoundariesLandInTheRightElement) {
  const SurfaceMesh mesh = curved_mesh();
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  // Feet 1e-7 (in xi) inside each element next to every edge and corner, offset 0.3
  // along the normal.
  const double in = 1e-7;
  const std::vector<Vec2> feet = {{in, 0.5}, {1 - in, 0.5},    {0.5, in},    {0.5, 1 - in},
                                  {in, in},  {1 - in, 1 - in}, {in, 1 - in}, {1 - in, in}};
  for (Index e = 0; e < mesh.n_elements(); ++e)
    for (const Vec2& xi : feet)
      for (double h : {-0.3, 0.3}) {
        const auto s = field.evaluate3(e, xi, basis::kValues | basis::kFirst);
        const Vec3 p = s.x + h * unit_normal(s);
        const Projection r = projector.project(p);
        ASSERT_EQ(r.status, Status::kConverged) << r.brief();
        EXPECT_EQ(r.element, e) << "xi=" << xi.transpose() << " " << r.brief();
        EXPECT_NEAR(r.xi[0], xi[0], 1e-9) << r.brief();
        EXPECT_NEAR(r.xi[1], xi[1], 1e-9) << r.brief();
        EXPECT_NEAR(r.distance, std::abs(h), 1e-9);
      }
  // Sweep across the element columns at y = 12: the global coordinate of the foot,
  // 10 * (column + xi1), grows continuously and the foot matches the surface.
  double previous = -1.0;
  const double dt = 0.01;
  for (double t = 5.0; t <= 35.0; t += dt) {
    const Vec3 p(t, 12.0, Height::f(t, 12.0) + 0.5);
    const Projection r = projector.project(p);
    ASSERT_EQ(r.status, Status::kConverged) << r.brief();
    const double s = 10.0 * (static_cast<double>(r.element % 4) + r.xi[0]);
    EXPECT_NEAR(s, r.point.x(), 1e-9);
    if (previous >= 0.0) {
      EXPECT_GT(s, previous) << "t=" << t;
      EXPECT_LT(s - previous, 2.0 * dt) << "t=" << t;
    }
    previous = s;
  }
}

TEST(ProjectionTest, BeyondFreeEdgeReportsOnFreeEdge) {
  const SurfaceMesh mesh = flat_mesh();
  const SurfaceProjector projector(mesh, mesh.geometry());
  {
    // 5 mm beyond the edge x = 40, 3 mm above: foot (40, 12, 0) in element 7 (column 3, row 1).
    const Projection r = projector.project(Vec3(45.0, 12.0, 3.0));
    EXPECT_EQ(r.status, Status::kOnFreeEdge) << r.brief();
    EXPECT_EQ(r.element, 7);
    EXPECT_EQ(r.xi[0], 1.0);
    EXPECT_NEAR(r.xi[1], 0.2, kXiTol);
    EXPECT_NEAR(r.distance, std::sqrt(34.0), kDistTol);
    EXPECT_LT((r.point - Vec3(40.0, 12.0, 0.0)).norm(), kDistTol);
  }
  {
    // Beyond the corner (0, 0): foot at the corner node.
    const Projection r = projector.project(Vec3(-3.0, -4.0, 2.0));
    EXPECT_EQ(r.status, Status::kOnFreeEdge) << r.brief();
    EXPECT_EQ(r.element, 0);
    EXPECT_EQ(r.xi[0], 0.0);
    EXPECT_EQ(r.xi[1], 0.0);
    EXPECT_NEAR(r.distance, std::sqrt(29.0), kDistTol);
  }
  {
    // Beyond the edge y = 30 (row 2), starting from a refine() in the far corner element.
    const Projection r = projector.refine(Vec3(25.0, 31.0, -1.0), 0, Vec2(0.5, 0.5));
    EXPECT_EQ(r.status, Status::kOnFreeEdge) << r.brief();
    EXPECT_EQ(r.element, 10);
    EXPECT_NEAR(r.xi[0], 0.5, kXiTol);
    EXPECT_EQ(r.xi[1], 1.0);
    EXPECT_NEAR(r.distance, std::sqrt(2.0), kDistTol);
  }
  {
    // Right above the free edge: the foot is on the edge, no tangential part.
    const Projection r = projector.project(Vec3(40.0, 12.0, 3.0));
    EXPECT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_NEAR(r.distance, 3.0, kDistTol);
    EXPECT_NEAR(r.point.x(), 40.0, kDistTol);
  }
}

TEST(ProjectionTest, DiskApexPointAboveCentre) {
  const Vec3 centre(1.0, 2.0, 3.0);
  const int n_sectors = 8;
  const SurfaceMesh mesh = make_disk_mesh(centre, Vec3::UnitX(), Vec3::UnitY(), 10.0, 3, n_sectors);
  const SurfaceProjector projector(mesh, mesh.geometry());
  for (double h : {4.0, -2.5, 1e-3}) {
    const Projection r = projector.project(centre + Vec3(0, 0, h));
    EXPECT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_TRUE(r.xi.allFinite() && r.point.allFinite() && std::isfinite(r.distance));
    EXPECT_LT(r.element, n_sectors) << "apex belongs to the collapsed ring";
    EXPECT_NEAR(r.distance, std::abs(h), 1e-9) << r.brief();
    EXPECT_LT((r.point - centre).norm(), 1e-8) << r.brief();
    EXPECT_NEAR(r.xi[1], 0.0, 1e-8);
  }
  // In the plane near the apex, in every sector: distance ~0, the right sector.
  for (int j = 0; j < n_sectors; ++j) {
    const double th = (j + 0.5) * 2.0 * kPi / n_sectors;
    const Vec3 p = centre + 0.05 * Vec3(std::cos(th), std::sin(th), 0.0) + Vec3(0, 0, 0.2);
    const Projection r = projector.project(p);
    EXPECT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_EQ(r.element, j) << r.brief();
    EXPECT_NEAR(r.distance, 0.2, 1e-9);
    // refine() from the opposite sector walks through the apex.
    const Index opposite = (j + n_sectors / 2) % n_sectors;
    const Projection w = projector.refine(p, opposite, Vec2(0.5, 0.5));
    EXPECT_EQ(w.status, Status::kConverged) << w.brief();
    EXPECT_EQ(w.element, j) << w.brief();
    EXPECT_NEAR(w.distance, 0.2, 1e-9) << w.brief();
  }
}

TEST(ProjectionTest, DomeWithCollapsedPoleFindsTheGlobalMinimum) {
  const double radius = 10.0;
  const SurfaceMesh mesh = dome_mesh(radius, 4, 8);
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  // Above and below the pole (below: inside the dome, beyond the centre of
  // curvature for starts away from the pole).
  for (double z : {14.0, 10.5, 9.0, 6.0}) {
    const Projection r = projector.project(Vec3(0, 0, z));
    EXPECT_EQ(r.status, Status::kConverged) << r.brief();
    EXPECT_TRUE(r.xi.allFinite() && r.point.allFinite());
    EXPECT_NEAR(r.distance, std::abs(z - radius), 1e-9) << r.brief();
    EXPECT_LT((r.point - Vec3(0, 0, radius)).norm(), 1e-8) << r.brief();
  }
  // Random points around the dome, including near the pole and inside.
  const std::vector<Vec3> sample = dense_sample(field, 40);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uxy(-13.0, 13.0), uz(-3.0, 14.0), upole(-0.5, 0.5);
  for (int k = 0; k < 80; ++k) {
    const Vec3 p = k < 20 ? Vec3(upole(rng), upole(rng), radius + 4.0 * upole(rng)) : Vec3(uxy(rng), uxy(rng), uz(rng));
    const Projection r = projector.project(p);
    ASSERT_TRUE(r.ok()) << r.brief() << " p=" << p.transpose();
    EXPECT_TRUE(r.xi.allFinite() && std::isfinite(r.distance));
    EXPECT_LE(r.distance, min_distance(sample, p) + 1e-12) << r.brief() << " p=" << p.transpose();
    if (r.status == Status::kConverged && r.xi[1] > 1e-6) expect_residual_normal(field, p, r);
  }
}

TEST(ProjectionTest, ResultsDoNotDependOnThreadCount) {
  const SurfaceMesh mesh = curved_mesh();
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> ux(-3.0, 43.0), uy(-3.0, 33.0), uz(-2.0, 2.0);
  Points3 points(5000, 3);
  for (Index i = 0; i < points.rows(); ++i) {
    const double x = ux(rng), y = uy(rng);
    points.row(i) = Vec3(x, y, Height::f(x, y) + uz(rng)).transpose();
  }
  ProjectionOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const auto r1 = SurfaceProjector(mesh, mesh.geometry(), one).project_all(points);
  const auto r2 = SurfaceProjector(mesh, mesh.geometry(), two).project_all(points);
  ASSERT_EQ(r1.size(), r2.size());
  int on_edge = 0;
  for (std::size_t i = 0; i < r1.size(); ++i) {
    ASSERT_EQ(r1[i].element, r2[i].element) << i;
    ASSERT_EQ(r1[i].xi, r2[i].xi) << i;
    ASSERT_EQ(r1[i].point, r2[i].point) << i;
    ASSERT_EQ(r1[i].distance, r2[i].distance) << i;
    ASSERT_EQ(r1[i].status, r2[i].status) << i;
    ASSERT_EQ(r1[i].iterations, r2[i].iterations) << i;
    ASSERT_TRUE(r1[i].ok()) << r1[i].brief();
    on_edge += r1[i].status == Status::kOnFreeEdge;
  }
  EXPECT_GT(on_edge, 0);
  // The batch equals the single-point call.
  const SurfaceProjector single(mesh, mesh.geometry());
  for (Index i = 0; i < points.rows(); i += 97) {
    const Projection r = single.project(Vec3(points.row(i).transpose()));
    EXPECT_EQ(r.xi, r1[static_cast<std::size_t>(i)].xi) << i;
    EXPECT_EQ(r.element, r1[static_cast<std::size_t>(i)].element) << i;
  }
}

TEST(ProjectionTest, RefineWalksFromWrongElement) {
  const SurfaceMesh mesh = curved_mesh();
  const fe::SurfaceField field(mesh, mesh.geometry());
  const SurfaceProjector projector(mesh, mesh.geometry());
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> uxi(0.05, 0.95), uh(-1.0, 1.0);
  for (Index target = 0; target < mesh.n_elements(); ++target) {
    const Vec2 xi(uxi(rng), uxi(rng));
    const auto s = field.evaluate3(target, xi, basis::kValues | basis::kFirst);
    const double h = uh(rng);
    const Vec3 p = s.x + h * unit_normal(s);
    const Index start = mesh.n_elements() - 1 - target;  // the opposite corner for corners
    const Projection r = projector.refine(p, start, Vec2(0.5, 0.5));
    ASSERT_EQ(r.status, Status::kConverged) << "from " << start << ": " << r.brief();
    EXPECT_EQ(r.element, target) << r.brief();
    EXPECT_NEAR(r.xi[0], xi[0], 1e-9);
    EXPECT_NEAR(r.xi[1], xi[1], 1e-9);
    EXPECT_NEAR(r.distance, std::abs(h), 1e-9);
    // Starting at the answer converges at once.
    const Projection again = projector.refine(p, r.element, r.xi);
    EXPECT_EQ(again.element, r.element);
    EXPECT_LE(again.iterations, 2);
  }
}

// The batch refine from the global answers of a slightly different surface (the
// alternation of fit and projection in gsa) finds what a global search finds.
TEST(ProjectionTest, RefineAllFromNearbyStartsMatchesTheGlobalSearch) {
  const SurfaceMesh mesh = curved_mesh();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> ux(0.5, 39.5), uy(0.5, 29.5), uz(-1.0, 1.0);
  Points3 points(3000, 3);
  for (Index i = 0; i < points.rows(); ++i) {
    const double x = ux(rng), y = uy(rng);
    points.row(i) = Vec3(x, y, Height::f(x, y) + uz(rng)).transpose();
  }
  MatX moved = mesh.geometry();
  for (Index node = 0; node < mesh.n_nodes(); ++node)
    moved(SurfaceMesh::dof(node, kValue), 2) += 0.05 * std::sin(0.3 * static_cast<double>(node));
  const std::vector<Projection> before = SurfaceProjector(mesh, mesh.geometry()).project_all(points);
  std::vector<Index> elements;
  std::vector<Vec2> xi;
  for (const Projection& r : before) {
    elements.push_back(r.element);
    xi.push_back(r.xi);
  }
  const SurfaceProjector projector(mesh, moved);
  const std::vector<Projection> global = projector.project_all(points);
  const std::vector<Projection> refined = projector.refine_all(points, elements, xi);
  ASSERT_EQ(refined.size(), global.size());
  for (std::size_t i = 0; i < global.size(); ++i) {
    ASSERT_TRUE(refined[i].ok()) << refined[i].brief();
    EXPECT_NEAR(refined[i].distance, global[i].distance, 1e-9) << i;
    EXPECT_LT((refined[i].point - global[i].point).norm(), 1e-7) << i;
  }
  EXPECT_THROW(projector.refine_all(points, {}, {}), InputError);
}

TEST(ProjectionTest, BadInputFailsCleanly) {
  const SurfaceMesh mesh = flat_mesh();
  const SurfaceProjector projector(mesh, mesh.geometry());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(projector.project(Vec3(nan, 0, 0)).status, Status::kFailed);
  EXPECT_EQ(projector.refine(Vec3(1, 1, 1), -1, Vec2(0.5, 0.5)).status, Status::kFailed);
  EXPECT_EQ(projector.refine(Vec3(1, 1, 1), mesh.n_elements(), Vec2(0.5, 0.5)).status, Status::kFailed);
  EXPECT_FALSE(Projection{}.ok());
  EXPECT_THROW(SurfaceProjector(mesh, MatX::Zero(mesh.n_dofs(), 2)), InputError);
  EXPECT_THROW(SurfaceProjector(mesh, MatX::Zero(mesh.n_dofs() - 1, 3)), InputError);
  EXPECT_EQ(projector.n_samples(), mesh.n_elements() * 36);
}

TEST(ProjectionOptionsTest, ValidateNamesTheOption) {
  auto message = [](ProjectionOptions o) -> std::string {
    try {
      o.validate();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message({}), "");
  ProjectionOptions o;
  o.candidates = 0;
  EXPECT_NE(message(o).find("candidates"), std::string::npos);
  o = {};
  o.samples_per_edge = 0;
  EXPECT_NE(message(o).find("samples_per_edge"), std::string::npos);
  o = {};
  o.max_iterations = 0;
  EXPECT_NE(message(o).find("max_iterations"), std::string::npos);
  o = {};
  o.xi_tolerance = -1.0;
  EXPECT_NE(message(o).find("xi_tolerance"), std::string::npos);
  o = {};
  o.threads = -2;
  EXPECT_NE(message(o).find("threads"), std::string::npos);
  const SurfaceMesh mesh = flat_mesh();
  EXPECT_THROW(SurfaceProjector(mesh, mesh.geometry(), o), InputError);
}

}  // namespace
}  // namespace sf::mesh
