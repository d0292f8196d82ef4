// Tests of the rigid registration (common/fe/registration.hpp): exact recovery of known
// motions, robustness to gross outliers, and ICP onto a fitted Hermite surface.

#include "common/fe/registration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

#include "common/fe/surface_field.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::fe {
namespace {

constexpr double kRotTol = 1e-11;    // |R - R_exact| (Frobenius) recovered from exact pairs
constexpr double kTransTol = 1e-9;   // mm, translation from exact pairs on a ~50 mm part
constexpr double kIcpRotTol = 1e-9;  // ICP onto an exact surface (projection good to ~1e-12 mm)
constexpr double kIcpTransTol = 1e-7;

RigidTransform known_motion() {
  RigidTransform t;
  t.rotation = Eigen::AngleAxisd(0.35, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  t.translation = Vec3(12.5, -7.25, 3.0);
  return t;
}

Points3 random_points(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-25.0, 25.0);
  Points3 p(n, 3);
  for (Index i = 0; i < n; ++i) p.row(i) = Vec3(u(rng), u(rng), 0.2 * u(rng)).transpose();
  return p;
}

TEST(Registration, BestFitRecoversAKnownMotionExactly) {
  const Points3 from = random_points(50, test::kSeed);
  const RigidTransform t = known_motion();
  const RigidTransform got = best_fit_rigid(from, t.apply_all(from));
  EXPECT_LT((got.rotation - t.rotation).norm(), kRotTol);
  EXPECT_LT((got.translation - t.translation).norm(), kTransTol);
  EXPECT_NEAR(got.rotation.determinant(), 1.0, test::kRoundoff);
}

TEST(Registration, ComposeAndInverse) {
  const RigidTransform t = known_motion();
  const RigidTransform id = t * t.inverse();
  EXPECT_LT((id.rotation - Mat3::Identity()).norm(), test::kRoundoff);
  EXPECT_LT(id.translation.norm(), 1e-12);
  EXPECT_NEAR(t.angle_deg(), 0.35 * 180.0 / kPi, 1e-10);
}

TEST(Registration, RobustFitIgnoresGrossOutliers) {
  const Index n = 200;
  const Points3 from = random_points(n, test::kSeed + 1);
  const RigidTransform t = known_motion();
  Points3 to = t.apply_all(from);
  std::mt19937 rng(test::kSeed);
  std::uniform_int_distribution<Index> pick(0, n - 1);
  std::vector<bool> moved(static_cast<std::size_t>(n), false);
  for (int k = 0; k < 30; ++k) {  // 15 % of the marks 3..8 mm off
    const Index i = pick(rng);
    to.row(i) += Vec3(3.0 + k * 0.17, -2.0, 5.0).transpose();
    moved[static_cast<std::size_t>(i)] = true;
  }
  to.row(7).setConstant(std::nan(""));  // a missing mark
  const RegistrationReport rep = robust_rigid_fit(from, to);
  ASSERT_EQ(rep.status, RegistrationReport::Status::kConverged) << rep.brief();
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), kRotTol);
  EXPECT_LT((rep.transform.translation - t.translation).norm(), kTransTol);
  for (Index i = 0; i < n; ++i) {
    if (i == 7) {
      EXPECT_FALSE(rep.used[7]);
      EXPECT_TRUE(std::isnan(rep.distances[7]));
      continue;
    }
    EXPECT_EQ(rep.used[static_cast<std::size_t>(i)], !moved[static_cast<std::size_t>(i)]) << "point " << i;
  }
  EXPECT_LT(rep.rms, 1e-9);
  EXPECT_GT(rep.rms_all, 1.0);
}

TEST(Registration, RobustFitWithNoiseStaysWithinTheNoise) {
  const Index n = 400;
  const Points3 from = random_points(n, test::kSeed + 2);
  const RigidTransform t = known_motion();
  Points3 to = t.apply_all(from);
  std::mt19937 rng(test::kSeed);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (Index i = 0; i < n; ++i) to.row(i) += Vec3(noise(rng), noise(rng), noise(rng)).transpose();
  const RegistrationReport rep = robust_rigid_fit(from, to);
  ASSERT_TRUE(rep.ok());
  // Translation error ~ sigma / sqrt(n) = 1e-3 mm; rotation ~ sigma / (sqrt(n) * 15 mm).
  EXPECT_LT((rep.transform.translation - t.translation).norm(), 5e-3);
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), 5e-4);
  EXPECT_NEAR(rep.rms, 0.02 * std::sqrt(3.0), 0.01);
}

TEST(Registration, TooFewPointsFailWithAMessage) {
  Points3 a(2, 3);
  a << 0, 0, 0, 1, 0, 0;
  const RegistrationReport rep = robust_rigid_fit(a, a);
  EXPECT_EQ(rep.status, RegistrationReport::Status::kFailed);
  EXPECT_NE(rep.message.find("at least 3"), std::string::npos);
}

// z = f(x, y), cubic in each of x and y, so the bicubic Hermite mesh reproduces it exactly;
// curved both ways and not symmetric, so a rigid motion onto it is unique.
struct Height {
  static double f(double x, double y) {
    return 0.02 * (x - 20) * (x - 20) - 0.015 * (y - 15) * (y - 15) + 0.0004 * x * y * y;
  }
  static double fx(double x, double y) { return 0.04 * (x - 20) + 0.0004 * y * y; }
  static double fy(double x, double y) { return -0.03 * (y - 15) + 0.0008 * x * y; }
  static double fxy(double, double y) { return 0.0008 * y; }
};

mesh::SurfaceMesh curved_mesh() {
  mesh::SurfaceMesh m = mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 40.0, 30.0, 4, 3);
  for (Index node = 0; node < m.n_nodes(); ++node) {
    const Vec3 q = m.node_position(node);
    const double x = q.x(), y = q.y();
    m.geometry().row(mesh::SurfaceMesh::dof(node, mesh::kValue)) = Vec3(x, y, Height::f(x, y)).transpose();
    m.geometry().row(mesh::SurfaceMesh::dof(node, mesh::kD1)) = Vec3(1, 0, Height::fx(x, y)).transpose();
    m.geometry().row(mesh::SurfaceMesh::dof(node, mesh::kD2)) = Vec3(0, 1, Height::fy(x, y)).transpose();
    m.geometry().row(mesh::SurfaceMesh::dof(node, mesh::kD12)) = Vec3(0, 0, Height::fxy(x, y)).transpose();
  }
  return m;
}

// Points on the surface, inside a margin from its edges (so no foot point ends on an edge).
Points3 surface_points(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(3.0, 37.0), uy(3.0, 27.0);
  Points3 p(n, 3);
  for (Index i = 0; i < n; ++i) {
    const double x = ux(rng), y = uy(rng);
    p.row(i) = Vec3(x, y, Height::f(x, y)).transpose();
  }
  return p;
}

RigidTransform small_motion() {
  RigidTransform t;
  t.rotation = Eigen::AngleAxisd(0.08, Vec3(0.2, 0.6, 0.77).normalized()).toRotationMatrix();
  t.translation = Vec3(1.5, -0.8, 0.6);
  return t;
}

TEST(Registration, IcpOntoAnExactSurfaceRecoversTheMotionToRoundoff) {
  const mesh::SurfaceMesh m = curved_mesh();
  const Points3 on = surface_points(300, test::kSeed);
  const RigidTransform t = small_motion();
  const Points3 moved = t.inverse().apply_all(on);  // measured part misplaced by t^-1
  const RegistrationReport rep = register_to_surface(moved, m, m.geometry());
  ASSERT_EQ(rep.status, RegistrationReport::Status::kConverged) << rep.brief();
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), kIcpRotTol) << rep.brief();
  EXPECT_LT((rep.transform.translation - t.translation).norm(), kIcpTransTol) << rep.brief();
  EXPECT_LT(rep.rms, 1e-9);
  EXPECT_EQ(rep.n_used, 300);
}

TEST(Registration, IcpIsRobustToOutliersAndMissingPoints) {
  const mesh::SurfaceMesh m = curved_mesh();
  Points3 on = surface_points(300, test::kSeed + 3);
  for (Index i = 0; i < 300; i += 10) on(i, 2) += 4.0;  // 10 % gross outliers, 4 mm off the surface
  on.row(5).setConstant(std::nan(""));
  const RigidTransform t = small_motion();
  const RegistrationReport rep = register_to_surface(t.inverse().apply_all(on), m, m.geometry());
  ASSERT_TRUE(rep.ok()) << rep.brief();
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), kIcpRotTol) << rep.brief();
  EXPECT_LT((rep.transform.translation - t.translation).norm(), kIcpTransTol) << rep.brief();
  for (Index i = 0; i < 300; i += 10) EXPECT_FALSE(rep.used[static_cast<std::size_t>(i)]) << "outlier " << i;
  EXPECT_FALSE(rep.used[5]);
  EXPECT_TRUE(std::isnan(rep.distances[5]));
}

TEST(Registration, IcpWithNoiseStaysWithinTheNoise) {
  const mesh::SurfaceMesh m = curved_mesh();
  Points3 on = surface_points(1000, test::kSeed + 4);
  std::mt19937 rng(test::kSeed);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (Index i = 0; i < on.rows(); ++i) on.row(i) += Vec3(noise(rng), noise(rng), noise(rng)).transpose();
  const RigidTransform t = small_motion();
  const RegistrationReport rep = register_to_surface(t.inverse().apply_all(on), m, m.geometry());
  ASSERT_TRUE(rep.ok()) << rep.brief();
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), 2e-3) << rep.brief();
  EXPECT_LT((rep.transform.translation - t.translation).norm(), 0.05) << rep.brief();
  EXPECT_LT(rep.rms, 0.05);
}

TEST(Registration, IcpFindsALargeMisplacementFromThePrincipalAxes) {
  const mesh::SurfaceMesh m = curved_mesh();
  const Points3 on = surface_points(400, test::kSeed + 5);
  RigidTransform t;
  t.rotation = Eigen::AngleAxisd(2.0, Vec3(0.1, 0.2, 1.0).normalized()).toRotationMatrix();
  t.translation = Vec3(60.0, -30.0, 10.0);
  const RegistrationReport rep = register_to_surface(t.inverse().apply_all(on), m, m.geometry());
  ASSERT_TRUE(rep.ok()) << rep.brief();
  EXPECT_LT((rep.transform.rotation - t.rotation).norm(), kIcpRotTol) << rep.brief() << " start " << rep.start;
  EXPECT_LT((rep.transform.translation - t.translation).norm(), kIcpTransTol) << rep.brief();
}

}  // namespace
}  // namespace sf::fe
