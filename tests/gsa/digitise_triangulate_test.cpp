// Triangulation (gsa/digitise/triangulate.hpp): exact recovery, a bad view dropped, the
// reprojection-error limit, and the perspective bias of a disc's centroid against a dense
// numerical integration over the projected disc.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "gsa/digitise/triangulate.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa::digitise {
namespace {

Rig three_cameras() {
  Rig rig;
  for (int k = 0; k < 3; ++k) {
    Camera c;
    c.width = 1632;
    c.height = 1224;
    c.fx = c.fy = 2400;
    c.cx = 816;
    c.cy = 612;
    c.distortion = {-0.09, 0.1, 2e-4, -1e-4, 0};
    const double a = 2 * kPi * k / 3;
    const Vec3 pos(110 * std::cos(a), 110 * std::sin(a), 420);
    const Vec3 z = (-pos).normalized(), y = (Vec3(0, -1, 0) - Vec3(0, -1, 0).dot(z) * z).normalized();
    c.R.row(0) = y.cross(z);
    c.R.row(1) = y;
    c.R.row(2) = z;
    c.t = -c.R * pos;
    rig.cameras.push_back(c);
  }
  return rig;
}

std::vector<Observation> observe(const Rig& rig, const Vec3& X) {
  std::vector<Observation> o;
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) o.push_back({static_cast<Index>(c), rig.cameras[c].project(X)});
  return o;
}

TEST(DigitiseTriangulate, RecoversPointsAndDropsABadView) {
  {  // exact observations give the point
    const Rig rig = three_cameras();
    for (const Vec3& X : {Vec3(0, 0, 0), Vec3(60, -40, 25), Vec3(-70, 70, -5)}) {
      const TriangulatedPoint p = triangulate(rig, observe(rig, X));
      ASSERT_TRUE(p.ok) << p.why;
      EXPECT_LT((p.X - X).norm(), 1e-9);
      EXPECT_LT(p.rms_px, 1e-8);
      EXPECT_EQ(p.used.size(), 3u);
    }
  }
  {  // noise gives small errors and abad view is dropped
    const Rig rig = three_cameras();
    std::mt19937 rng(sf::test::kSeed);
    std::normal_distribution<double> n(0, 0.05);
    const Vec3 X(12, 34, 5);
    auto obs = observe(rig, X);
    for (Observation& o : obs) o.pixel += Vec2(n(rng), n(rng));
    const TriangulatedPoint p = triangulate(rig, obs);
    ASSERT_TRUE(p.ok);
    EXPECT_LT((p.X - X).norm(), 0.05);  // 0.05 px noise at 0.18 mm/px
    obs[1].pixel += Vec2(6, -4);        // a mislocated mark in camera 1
    const TriangulatedPoint q = triangulate(rig, obs);
    ASSERT_TRUE(q.ok) << q.why;
    EXPECT_EQ(q.used.size(), 2u);
    EXPECT_LT((q.X - X).norm(), 0.1);
    // With two views only, the disagreement is reported, not hidden.
    const TriangulatedPoint r = triangulate(rig, {obs[0], obs[1]});
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.why.find("reprojection"), std::string::npos);
  }
}

TEST(DigitiseTriangulate, DiscCentroidOffsetMatchesDenseIntegration) {
  const Rig rig = three_cameras();
  const Camera& cam = rig.cameras[0];
  const Vec3 c(40, -30, 20);
  const Vec3 n = Vec3(0.5, 0.3, 1).normalized();  // a steep facet
  const double r = 1.2;
  const Vec2 offset = disc_centroid_offset(cam, c, n, r);
  // Dense polar integration of the image centroid: sum of x |J| over the disc's area.
  const Vec3 a = Vec3::UnitX().cross(n).normalized(), b = n.cross(a);
  auto img = [&](double s, double t) { return cam.project(c + s * a + t * b); };
  double A = 0;
  Vec2 C = Vec2::Zero();
  const int nr = 200, nt = 256;
  for (int i = 0; i < nr; ++i)
    for (int k = 0; k < nt; ++k) {
      const double rho = r * (i + 0.5) / nr, th = 2 * kPi * (k + 0.5) / nt;
      const double s = rho * std::cos(th), t = rho * std::sin(th), h = 1e-5;
      Mat2 J;
      J.col(0) = (img(s + h, t) - img(s - h, t)) / (2 * h);
      J.col(1) = (img(s, t + h) - img(s, t - h)) / (2 * h);
      const double dA = std::abs(J.determinant()) * rho * (r / nr) * (2 * kPi / nt);
      A += dA;
      C += dA * img(s, t);
    }
  const Vec2 dense = C / A - cam.project(c);
  EXPECT_GT(offset.norm(), 1e-3);            // the bias is real here ...
  EXPECT_LT((offset - dense).norm(), 2e-4);  // ... and computed right
  EXPECT_NEAR(disc_image_area(cam, c, n, r), A, 1e-3 * A);
  // Seen head-on without distortion the disc's image is a circle centred on the projection.
  Camera head_on = cam;
  head_on.distortion = {};
  head_on.R = Mat3::Identity();
  head_on.t = Vec3(0, 0, 300);
  EXPECT_LT(disc_centroid_offset(head_on, Vec3(0, 0, 0), Vec3(0, 0, 1), 1.0).norm(), 1e-9);
}

}  // namespace
}  // namespace sf::gsa::digitise
