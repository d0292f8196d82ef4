// Tests of the rigid tool shapes and motions (forming/contact/tool_shape.hpp,
// forming/contact/rigid_tool.hpp):
//  * every analytic shape is a signed distance: |n| = 1, n = FD gradient of the gap,
//    dn/dx = FD Hessian (symmetric), and x - g n lies on the surface (gap 0 there);
//  * known values: gaps at points whose distance is known by construction (sphere,
//    cylinder, the punch's end face, side and fillet, the die's top face, opening wall
//    and edge, for a circular and a slotted opening);
//  * a meshed tool (STL) agrees with the analytic sphere it triangulates, to the chord
//    error, and its (unsymmetric) derivatives match finite differences;
//  * motions: displacement and velocity agree (FD), tables interpolate and hold.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/stl.hpp"
#include "forming/contact/rigid_tool.hpp"
#include "forming/contact/tool_shape.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::forming {
namespace {

constexpr double kFdStep = 1e-6;  // mm
constexpr double kFdRel = 1e-6;   // derivatives vs central differences (measured ~1e-9)
constexpr double kExact = 1e-12;  // mm, gaps known in closed form

struct Named {
  std::string name;
  std::shared_ptr<const ToolShape> shape;
};

std::vector<Named> analytic_shapes() {
  DieOpening circle;
  circle.radius = 20.0;
  DieOpening slot;
  slot.slot = true;
  slot.half_width = 15.0;
  slot.along = Vec3(0.0, 1.0, 0.2);  // not in the top face: projected onto it
  return {{"plane", make_plane(Vec3(1, 2, 3), Vec3(0.2, -0.3, 1.0))},
          {"sphere", make_sphere(Vec3(0, 0, 30), 25.0)},
          {"cylinder", make_cylinder(Vec3(0, 0, 10), Vec3(0, 1, 0.1), 8.0)},
          {"punch", make_punch(Vec3(0, 0, 5), Vec3(0, 0, -1), 20.0, 5.0)},
          {"die (circle)", make_die(Vec3(0, 0, 0), Vec3(0, 0, 1), circle, 4.0)},
          {"die (slot)", make_die(Vec3(0, 0, 0), Vec3(0, 0, 1), slot, 4.0)}};
}

TEST(ToolShape, AnalyticShapesAreSignedDistancesWithExactDerivatives) {
  std::mt19937 rng(test::kSeed + 11);
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  for (const Named& s : analytic_shapes()) {
    int tested = 0;
    for (int k = 0; k < 400 && tested < 60; ++k) {
      const Vec3 x(u(rng), u(rng), u(rng) * 0.5 + 5.0);
      const ToolPoint t = s.shape->evaluate(x);
      if (!t.in_front || std::abs(t.gap) > 15.0) continue;
      ++tested;
      EXPECT_NEAR(t.normal.norm(), 1.0, test::kRoundoff) << s.name;
      EXPECT_LT((t.gap_gradient - t.normal).norm(), test::kRoundoff) << s.name;
      Vec3 dg;
      Mat3 dn;
      for (int j = 0; j < 3; ++j) {
        Vec3 xp = x, xm = x;
        xp[j] += kFdStep;
        xm[j] -= kFdStep;
        const ToolPoint p = s.shape->evaluate(xp), m = s.shape->evaluate(xm);
        dg[j] = (p.gap - m.gap) / (2 * kFdStep);
        dn.col(j) = (p.normal - m.normal) / (2 * kFdStep);
      }
      EXPECT_LT((dg - t.normal).norm(), kFdRel) << s.name << " at " << x.transpose();
      EXPECT_LT((dn - t.normal_gradient).norm(), kFdRel * std::max(1.0, dn.norm()))
          << s.name << " at " << x.transpose();
      EXPECT_LT((t.normal_gradient - t.normal_gradient.transpose()).norm(), 1e-12) << s.name;
      // The foot point x - g n lies on the surface.
      EXPECT_NEAR(s.shape->evaluate(x - t.gap * t.normal).gap, 0.0, 1e-10) << s.name;
    }
    EXPECT_EQ(tested, 60) << s.name;
  }
}

TEST(ToolShape, KnownGaps) {
  const auto sphere = make_sphere(Vec3(0, 0, 30), 25.0);
  EXPECT_NEAR(sphere->evaluate(Vec3(0, 0, 0)).gap, 5.0, kExact);
  EXPECT_NEAR(sphere->evaluate(Vec3(0, 0, 10)).gap, -5.0, kExact);
  const auto cylinder = make_cylinder(Vec3(0, 0, 10), Vec3(1, 0, 0), 8.0);
  EXPECT_NEAR(cylinder->evaluate(Vec3(123, 0, 0)).gap, 2.0, kExact);
  // Punch pressing along -z, tip face at z = 5, radius 20, fillet 5.
  const auto punch = make_punch(Vec3(0, 0, 5), Vec3(0, 0, -1), 20.0, 5.0);
  EXPECT_NEAR(punch->evaluate(Vec3(3, 4, 2)).gap, 3.0, kExact);  // below the end face
  EXPECT_LT((punch->evaluate(Vec3(3, 4, 2)).normal - Vec3(0, 0, -1)).norm(), kExact);
  EXPECT_NEAR(punch->evaluate(Vec3(0, 23, 30)).gap, 3.0, kExact);  // beside the side
  const Vec3 fillet_centre(0, 15, 10);                             // (R - r, tip + r)
  const Vec3 dir = Vec3(0, 1, -1).normalized();
  EXPECT_NEAR(punch->evaluate(fillet_centre + 7.0 * dir).gap, 2.0, kExact);  // off the fillet
  EXPECT_NEAR(punch->evaluate(Vec3(0, 0, 6)).gap, -1.0, kExact);             // inside
  // Die: top face z = 0, circular opening radius 20, edge radius 4.
  DieOpening circle;
  circle.radius = 20.0;
  const auto die = make_die(Vec3(0, 0, 0), Vec3(0, 0, 1), circle, 4.0);
  EXPECT_NEAR(die->evaluate(Vec3(30, 0, 2)).gap, 2.0, kExact);    // above the top face
  EXPECT_NEAR(die->evaluate(Vec3(0, 17, -10)).gap, 3.0, kExact);  // in the opening, off the wall
  EXPECT_NEAR(die->evaluate(Vec3(0, 0, -10)).gap, 20.0, kExact);  // on the axis
  const Vec3 edge_centre(24, 0, -4);
  EXPECT_NEAR(die->evaluate(edge_centre + 5.0 * Vec3(-1, 0, 1).normalized()).gap, 1.0, kExact);
  DieOpening slot;
  slot.slot = true;
  slot.half_width = 15.0;
  slot.along = Vec3::UnitY();
  const auto slot_die = make_die(Vec3(0, 0, 0), Vec3(0, 0, 1), slot, 4.0);
  EXPECT_NEAR(slot_die->evaluate(Vec3(-12, 50, -10)).gap, 3.0, kExact);
  EXPECT_NEAR(slot_die->evaluate(Vec3(40, -7, 1)).gap, 1.0, kExact);
}

TEST(ToolShape, RejectsBadParameters) {
  EXPECT_THROW(make_sphere(Vec3::Zero(), -1.0), InputError);
  EXPECT_THROW(make_plane(Vec3::Zero(), Vec3::Zero()), InputError);
  EXPECT_THROW(make_punch(Vec3::Zero(), Vec3::UnitZ(), 5.0, 6.0), InputError);
  DieOpening slot;
  slot.slot = true;
  slot.half_width = 10.0;
  slot.along = Vec3::UnitZ();
  EXPECT_THROW(make_die(Vec3::Zero(), Vec3::UnitZ(), slot, 1.0), InputError);
}

// The triangulated sphere the analytic sphere is tessellated into.
io::TriangleMesh sphere_mesh(const ToolShape& sphere) {
  const ToolTessellation t = sphere.tessellate(Vec3::Zero(), Vec3::Zero());
  io::TriangleMesh m;
  m.vertices = t.points;
  m.triangles = t.triangles;
  return m;
}

TEST(ToolShape, MeshedSphereAgreesWithTheAnalyticOneAndHasExactDerivatives) {
  const auto sphere = make_sphere(Vec3(0, 0, 30), 25.0);
  const io::TriangleMesh m = sphere_mesh(*sphere);
  const auto meshed = make_mesh_tool(m);
  EXPECT_FALSE(meshed->symmetric());
  std::mt19937 rng(test::kSeed + 12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Chord error of 48 x 16 segments on R = 25: R (1 - cos(pi/16)) ~ 0.48 mm.
  const double chord = 25.0 * (1.0 - std::cos(kPi / 16));
  int derivative_checks = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 x = Vec3(0, 0, 30) + dir * (25.0 + 3.0 * u(rng));
    const ToolPoint a = sphere->evaluate(x), t = meshed->evaluate(x);
    EXPECT_NEAR(t.gap, a.gap, chord + 1e-9);
    EXPECT_LT((t.normal - a.normal).norm(), 0.1);  // smoothed normals follow the sphere's
    Vec3 dg;
    Mat3 dn;
    for (int j = 0; j < 3; ++j) {
      Vec3 xp = x, xm = x;
      xp[j] += kFdStep;
      xm[j] -= kFdStep;
      const ToolPoint p = meshed->evaluate(xp), q = meshed->evaluate(xm);
      dg[j] = (p.gap - q.gap) / (2 * kFdStep);
      dn.col(j) = (p.normal - q.normal) / (2 * kFdStep);
    }
    // Differences across region boundaries are no derivatives; most points are inside one.
    if ((dg - t.gap_gradient).norm() > 1e-3) continue;
    ++derivative_checks;
    EXPECT_LT((dg - t.gap_gradient).norm(), kFdRel);
    EXPECT_LT((dn - t.normal_gradient).norm(), kFdRel * std::max(1.0, dn.norm()));
  }
  EXPECT_GT(derivative_checks, 150);
}

TEST(ToolMotion, DisplacementAndVelocityAgree) {
  const std::vector<ToolMotion> motions = {
      ToolMotion::ramped(Vec3(1, -2, 3), Ramp::kSmooth, 2.0), ToolMotion::ramped(Vec3(0, 0, -5), Ramp::kLinear, 1.0),
      ToolMotion::constant_velocity(Vec3(0.5, 0, -1)),
      ToolMotion::table({{0.0, Vec3::Zero()}, {1.0, Vec3(0, 0, -2)}, {3.0, Vec3(1, 0, -2)}})};
  for (const ToolMotion& m : motions)
    for (double t : {0.13, 0.5, 0.77, 1.4, 2.5}) {
      const double h = 1e-6;
      const Vec3 fd = (m.displacement(t + h) - m.displacement(t - h)) / (2 * h);
      EXPECT_LT((fd - m.velocity(t)).norm(), 1e-6) << m.describe() << " at t = " << t;
    }
  const ToolMotion table = motions[3];
  EXPECT_LT((table.displacement(2.0) - Vec3(0.5, 0, -2)).norm(), kExact);
  EXPECT_LT((table.displacement(9.0) - Vec3(1, 0, -2)).norm(), kExact);
  EXPECT_LT((table.velocity(9.0)).norm(), kExact);
  EXPECT_LT((motions[0].displacement(5.0) - Vec3(1, -2, 3)).norm(), kExact);  // held after the ramp
  EXPECT_FALSE(ToolMotion::fixed().moves());
  EXPECT_THROW(ToolMotion::table({{1.0, Vec3::Zero()}, {1.0, Vec3::Zero()}}), InputError);
  EXPECT_THROW(ToolMotion::ramped(Vec3::Zero(), Ramp::kLinear, 0.0), InputError);
}

TEST(RigidTool, AMovedToolIsTheShapeShifted) {
  RigidTool tool{"punch", make_sphere(Vec3(0, 0, 30), 25.0), ToolMotion::ramped(Vec3(0, 0, -4), Ramp::kLinear, 2.0)};
  EXPECT_NEAR(tool.at(Vec3::Zero(), 0.0).gap, 5.0, kExact);
  EXPECT_NEAR(tool.at(Vec3::Zero(), 1.0).gap, 3.0, kExact);
  EXPECT_NEAR(tool.at(Vec3::Zero(), 2.0).gap, 1.0, kExact);
}

}  // namespace
}  // namespace sf::forming
