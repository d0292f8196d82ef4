// The strain formulas on their own (gsa/strain.hpp, docs/theory/strain.md "Strains" and
// "Fibres"), from tangent pairs G (undeformed) and g (deformed) built from known
// deformation gradients: exact principal stretches, directions and strain measures of a
// homogeneous deformation in any parameterisation, zero strain under rigid rotation and
// isometric bending, fibre stretch and trellis shear of a pin-jointed net.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "gsa/strain.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa {
namespace {

// Formulas on O(1) tangents: a 2 x 2 eigenproblem and a few products; measured ~1e-15.
constexpr double kExact = 1e-12;
// Angles in degrees from acos near well-separated directions.
constexpr double kExactDeg = 1e-9;

Mat3 rotation(double angle, const Vec3& axis) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

// |a . b| = 1 for unit vectors along the same line (directions have an arbitrary sign).
double misalignment(const Vec3& a, const Vec3& b) { return 1.0 - std::abs(a.normalized().dot(b.normalized())); }

// A homogeneous deformation x = F X of the sheet z = 0 with principal stretches l1 >= l2
// along the unit in-plane directions (cos t, sin t) and its normal, then a rotation R.
struct Homogeneous {
  double l1 = 1.3, l2 = 0.8, t = 0.4;
  Mat3 r = rotation(0.9, Vec3(1, -2, 0.5));
  Vec3 d1() const { return Vec3(std::cos(t), std::sin(t), 0); }
  Vec3 d2() const { return Vec3(-std::sin(t), std::cos(t), 0); }
  Mat3 f() const {
    return r *
           (l1 * d1() * d1().transpose() + l2 * d2() * d2().transpose() + Vec3::UnitZ() * Vec3::UnitZ().transpose());
  }
};

// Tangents of the sheet in some parameterisation: columns any two independent in-plane
// vectors (a skewed, stretched xi grid gives the same strains).
Mat32 tangents(const Vec3& a, const Vec3& b) {
  Mat32 G;
  G << a, b;
  return G;
}

TEST(GsaStrain, HomogeneousDeformationIsExactInAnyParameterisation) {
  const Homogeneous h;
  for (const Mat32& G : {tangents(Vec3::UnitX(), Vec3::UnitY()), tangents(Vec3(2, 0.3, 0), Vec3(-0.7, 0.5, 0)),
                         tangents(Vec3(0, 5, 0), Vec3(0.1, 0.1, 0))}) {
    const Mat32 g = h.f() * G;
    const auto s = surface_strain(G, g);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->lambda1, h.l1, kExact);
    EXPECT_NEAR(s->lambda2, h.l2, kExact);
    EXPECT_NEAR(s->green(0), 0.5 * (h.l1 * h.l1 - 1), kExact);
    EXPECT_NEAR(s->green(1), 0.5 * (h.l2 * h.l2 - 1), kExact);
    EXPECT_NEAR(s->engineering(0), h.l1 - 1, kExact);
    EXPECT_NEAR(s->true_strain(1), std::log(h.l2), kExact);
    EXPECT_NEAR(s->thickness_change_pct(), 100.0 * (1.0 / (h.l1 * h.l2) - 1.0), kExact);
    // Directions: the material line (cos t, sin t) on the blank, R F-mapped on the part.
    EXPECT_LT(misalignment(s->dir1_undeformed, h.d1()), kExact);
    EXPECT_LT(misalignment(s->dir2_undeformed, h.d2()), kExact);
    EXPECT_LT(misalignment(s->dir1_deformed, h.r * h.d1()), kExact);
    EXPECT_LT(misalignment(s->dir2_deformed, h.r * h.d2()), kExact);
    EXPECT_NEAR(s->dir1_deformed.norm(), 1.0, kExact);
    EXPECT_NEAR(std::abs(s->dir1_deformed.dot(s->dir2_deformed)), 0.0, kExact);
    EXPECT_LT(misalignment(s->normal_deformed, h.r * Vec3::UnitZ()), kExact);
  }
}

// A principal direction is an axis; its sign follows one convention whatever the
// parameterisation (the eigen solver's own sign depends on it): the deformed major direction
// points to +x (+y where it is across x), and (major, minor, normal) is right-handed on both
// surfaces. Without it, round-off chose opposite signs on neighbouring marks of symmetric parts.
TEST(GsaStrain, PrincipalDirectionsFollowOneSignConvention) {
  const Homogeneous h;
  const Vec3 a(2, 0.3, 0), b(-0.7, 0.5, 0);
  std::vector<SurfaceStrain> all;
  for (const Mat32& G : {tangents(a, b), tangents(b, a), tangents(-a, b), tangents(a, -b), tangents(-b, -a)}) {
    const auto s = surface_strain(G, h.f() * G);
    ASSERT_TRUE(s);
    EXPECT_GT(s->dir1_deformed.x(), 0.0);
    EXPECT_GT(s->dir1_deformed.cross(s->dir2_deformed).dot(s->normal_deformed), 0.5);
    EXPECT_GT(s->dir1_undeformed.cross(s->dir2_undeformed).dot(s->normal_undeformed), 0.5);
    all.push_back(*s);
  }
  for (const SurfaceStrain& s : all) {
    // The normals follow the parameterisation's handedness; the directions do not flip with it
    // beyond what the right-hand rule asks of the minor one.
    const double hand = s.normal_deformed.dot(all[0].normal_deformed);
    EXPECT_LT((s.dir1_deformed - all[0].dir1_deformed).norm(), kExact);
    EXPECT_LT((s.dir1_undeformed - all[0].dir1_undeformed).norm(), kExact);
    EXPECT_LT((s.dir2_deformed - hand * all[0].dir2_deformed).norm(), kExact);
  }
  // A major direction across x takes +y.
  Mat3 f = Mat3::Identity();
  f(1, 1) = 1.2;
  for (const Mat32& G : {tangents(Vec3::UnitX(), Vec3::UnitY()), tangents(Vec3::UnitY(), -Vec3::UnitX())}) {
    const auto s = surface_strain(G, f * G);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->dir1_deformed.y(), 1.0, kExact);
  }
}

// Rigid motion and isometric bending leave the metric alone: zero strain, on curved
// surfaces too (tangents anywhere in space).
TEST(GsaStrain, RigidRotationGivesZeroStrain) {
  std::mt19937 rng(test::kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    SCOPED_TRACE("sample " + std::to_string(k));
    const Mat32 G = tangents(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
    const Mat3 r = rotation(3.0 * u(rng), Vec3(u(rng), u(rng), u(rng)));
    const auto s = surface_strain(G, r * G);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->lambda1, 1.0, kExact);
    EXPECT_NEAR(s->lambda2, 1.0, kExact);
    EXPECT_NEAR(s->green(0), 0.0, kExact);
    EXPECT_NEAR(s->thickness_change_pct(), 0.0, 1e2 * kExact);
  }
}

// Ordering and signs: lambda1 >= lambda2 whatever the parameterisation's order, and
// compression is negative.
TEST(GsaStrain, MajorFirstAndCompressionNegative) {
  Homogeneous h;
  h.l1 = 0.7;  // both compressive, given the "wrong" way round
  h.l2 = 0.9;
  const Mat32 G = tangents(Vec3::UnitY(), Vec3::UnitX());
  const auto s = surface_strain(G, h.f() * G);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->lambda1, 0.9, kExact);
  EXPECT_NEAR(s->lambda2, 0.7, kExact);
  EXPECT_LT(s->green(0), 0.0);
  EXPECT_LT(s->true_strain(1), s->true_strain(0));
  EXPECT_GT(s->thickness_change_pct(), 0.0);  // an area shrinking sheet thickens
}

TEST(GsaStrain, DegenerateTangentsGiveNoStrain) {
  const Mat32 G = tangents(Vec3::UnitX(), Vec3::UnitY());
  EXPECT_FALSE(surface_strain(tangents(Vec3::UnitX(), Vec3::UnitX()), G));      // undeformed collapsed
  EXPECT_FALSE(surface_strain(G, tangents(Vec3::UnitX(), 2 * Vec3::UnitX())));  // deformed collapsed
  EXPECT_FALSE(surface_strain(G, tangents(Vec3::Zero(), Vec3::UnitY())));
  Mat32 nan = G;
  nan(0, 0) = std::nan("");
  EXPECT_FALSE(surface_strain(nan, G));
}

// A pin-jointed 0/90 net sheared by gamma: each family turns by gamma/2 towards the other
// and keeps its length, so both fibre stretches are 1 and the shear angle is gamma,
// whatever the parameterisation; a +-45 net under the same map stretches one family and
// shortens the other, by |F a0|.
TEST(GsaStrain, TrellisShearOfAPinJointedNet) {
  const double gamma_deg = 34.4, gamma = gamma_deg * kPi / 180.0;
  const Vec3 a1(std::cos(gamma / 2), std::sin(gamma / 2), 0), a2(std::sin(gamma / 2), std::cos(gamma / 2), 0);
  Mat3 f = Mat3::Identity();
  f.col(0) = a1;  // e1 -> a1, e2 -> a2
  f.col(1) = a2;
  const Mat3 r = rotation(0.3, Vec3(0.2, 1, 0.4));
  for (const Mat32& G : {tangents(Vec3::UnitX(), Vec3::UnitY()), tangents(Vec3(1, 1, 0), Vec3(-2, 1, 0))}) {
    const Mat32 g = r * f * G;
    const FibrePair net = fibre_pair(G, g, 0, 90);
    ASSERT_TRUE(net.state[0] && net.state[1]);
    EXPECT_NEAR(net.state[0]->stretch, 1.0, kExact);
    EXPECT_NEAR(net.state[1]->stretch, 1.0, kExact);
    EXPECT_NEAR(net.shear_angle_deg, gamma_deg, kExactDeg);
    EXPECT_LT(misalignment(net.state[0]->direction_deformed, r * a1), kExact);
    EXPECT_LT(misalignment(net.state[1]->direction_deformed, r * a2), kExact);
    EXPECT_LT(misalignment(*net.undeformed[0], Vec3::UnitX()), kExact);
    // +-45 degrees: the fibres along (1, -1) and (1, 1) on the blank.
    const FibrePair diag = fibre_pair(G, g, -45, 45);
    ASSERT_TRUE(diag.state[0] && diag.state[1]);
    const Vec3 b1 = f * Vec3(1, -1, 0).normalized(), b2 = f * Vec3(1, 1, 0).normalized();
    EXPECT_NEAR(diag.state[0]->stretch, b1.norm(), kExact);
    EXPECT_NEAR(diag.state[1]->stretch, b2.norm(), kExact);
    EXPECT_LT(diag.state[0]->stretch, 1.0);
    EXPECT_GT(diag.state[1]->stretch, 1.0);
    const double angle = std::acos(b1.normalized().dot(b2.normalized())) * 180.0 / kPi;
    EXPECT_NEAR(diag.shear_angle_deg, 90.0 - angle, kExactDeg);
  }
}

// The fibre angle is measured on the sheet from the X axis, anticlockwise about the normal
// G1 x G2; with X nearly normal to the sheet, from G1 instead.
TEST(GsaStrain, FibreAnglesAreMeasuredFromTheXAxisAboutTheNormal) {
  const Mat32 flat = tangents(Vec3::UnitX(), Vec3::UnitY());
  EXPECT_LT((*tangent_at_angle(flat, Vec3::UnitX(), 90) - Vec3::UnitY()).norm(), kExact);
  EXPECT_LT((*tangent_at_angle(flat, Vec3::UnitX(), 30) - Vec3(std::sqrt(3) / 2, 0.5, 0)).norm(), kExact);
  // A sheet tilted about Y: the X axis projected onto it, the normal G1 x G2.
  const Mat3 tilt = rotation(0.5, Vec3::UnitY());
  const Mat32 tilted = tilt * flat;
  const Vec3 t0 = *tangent_at_angle(tilted, Vec3::UnitX(), 0);
  EXPECT_LT(misalignment(t0, tilt * Vec3::UnitX()), kExact);
  EXPECT_NEAR(t0.dot(tilt * Vec3::UnitZ()), 0.0, kExact);  // in the tangent plane
  // The sheet x = const: X is its normal, so the angle counts from G1.
  const Mat32 wall = tangents(Vec3::UnitY(), Vec3::UnitZ());
  EXPECT_LT((*tangent_at_angle(wall, Vec3::UnitX(), 0) - Vec3::UnitY()).norm(), kExact);
  EXPECT_NEAR(trellis_shear_deg(90, Vec3::UnitX(), Vec3::UnitY()), 0.0, kExactDeg);
  EXPECT_NEAR(trellis_shear_deg(90, Vec3::UnitX(), Vec3(1, 1, 0).normalized()), 45.0, kExactDeg);
}

}  // namespace
}  // namespace sf::gsa
