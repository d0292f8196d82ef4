// Tests of closest points on triangulated surfaces (common/mesh/triangle_surface.hpp):
//  * the closest point agrees with a brute-force search over every facet;
//  * the gap and the smoothed normal's derivatives equal central finite differences
//    inside each region (facet interior, edge, vertex);
//  * the smoothed normal is continuous across facet edges (the facet normal is not);
//  * beyond the free edge of an open surface a point is not "in front".
#include "common/mesh/triangle_surface.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "common/core/error.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFdStep = 1e-6;       // mm, for O(1) geometry
constexpr double kFdRel = 1e-6;        // derivative vs central difference (measured ~1e-9)
constexpr double kBruteForce = 1e-12;  // mm, closest distance vs brute force

// A UV sphere of radius r (n_lat x n_lon), closed, outward-oriented.
TriangleSurface uv_sphere(double r, int n_lat, int n_lon) {
  std::vector<Vec3> pts = {Vec3(0, 0, -r)};
  for (int i = 1; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      const double th = -0.5 * kPi + kPi * i / n_lat, ph = 2 * kPi * j / n_lon;
      pts.emplace_back(r * std::cos(th) * std::cos(ph), r * std::cos(th) * std::sin(ph), r * std::sin(th));
    }
  pts.emplace_back(0, 0, r);
  const Index top = static_cast<Index>(pts.size()) - 1;
  auto ring = [&](int i, int j) { return static_cast<Index>(1 + (i - 1) * n_lon + (j % n_lon)); };
  std::vector<std::array<Index, 3>> tri;
  for (int j = 0; j < n_lon; ++j) tri.push_back({0, ring(1, j + 1), ring(1, j)});
  for (int i = 1; i + 1 < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      tri.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
      tri.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
    }
  for (int j = 0; j < n_lon; ++j) tri.push_back({ring(n_lat - 1, j), ring(n_lat - 1, j + 1), top});
  Points3 v(static_cast<Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) v.row(static_cast<Index>(i)) = pts[i].transpose();
  return TriangleSurface(std::move(v), std::move(tri));
}

double brute_force_distance(const TriangleSurface& s, const Vec3& x) {
  // Dense sampling of every facet (barycentric grid) bounds the distance from above;
  // the exact closest point must not be farther than the best sample.
  double best = std::numeric_limits<double>::infinity();
  const int n = 60;
  for (const auto& t : s.triangles()) {
    const Vec3 a = s.vertices().row(t[0]).transpose(), b = s.vertices().row(t[1]).transpose(),
               c = s.vertices().row(t[2]).transpose();
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double u = double(i) / n, v = double(j) / n;
        best = std::min(best, (a + u * (b - a) + v * (c - a) - x).norm());
      }
  }
  return best;
}

TEST(TriangleSurface, ClosestPointIsNoFartherThanAnyPointOfTheSurface) {
  const TriangleSurface s = uv_sphere(2.0, 6, 10);
  std::mt19937 rng(test::kSeed);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int k = 0; k < 20; ++k) {
    const Vec3 x(u(rng), u(rng), u(rng));
    const SurfaceClosestPoint c = s.closest(x);
    const double brute = brute_force_distance(s, x);
    EXPECT_LE(c.distance, brute + kBruteForce);
    EXPECT_GT(c.distance, brute - 2.0 * 2.0 * kPi / 10 / 60);  // samples lie within a grid cell of the surface
    // The barycentric coordinates reproduce the point.
    const auto& t = s.triangles()[static_cast<std::size_t>(c.triangle)];
    Vec3 p = Vec3::Zero();
    for (int i = 0; i < 3; ++i) p += c.barycentric[i] * s.vertices().row(t[i]).transpose();
    EXPECT_LT((p - c.point).norm(), test::kRoundoff);
    EXPECT_NEAR(c.normal.norm(), 1.0, test::kRoundoff);
    // Well outside the (inscribed) polyhedron the gap is positive, well inside negative.
    if (x.norm() > 2.5) {
      EXPECT_GT(c.gap, 0.0) << x.transpose();
    }
    if (x.norm() < 1.0) {
      EXPECT_LT(c.gap, 0.0) << x.transpose();
    }
  }
}

TEST(TriangleSurface, GapAndNormalDerivativesMatchFiniteDifferences) {
  const TriangleSurface s = uv_sphere(2.0, 6, 10);
  std::mt19937 rng(test::kSeed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int seen[3] = {0, 0, 0};
  // 600 points: with 200, the points whose finite differences stay in one edge region were
  // 3 (not more than 5) in the clang build of the sanitized tests (scripts/sanitize.sh).
  for (int k = 0; k < 600; ++k) {
    Vec3 x(u(rng), u(rng), u(rng));
    // Half inside, half outside (edge and vertex regions open up outside a convex surface).
    x = x.normalized() * (k % 2 == 0 ? 2.0 - 0.3 * std::abs(u(rng)) : 2.1 + 0.6 * std::abs(u(rng)));
    const SurfaceClosestPoint c = s.closest(x);
    Mat3 dn_fd;
    Vec3 dg_fd;
    bool same_region = true;
    for (int j = 0; j < 3; ++j) {
      Vec3 xp = x, xm = x;
      xp[j] += kFdStep;
      xm[j] -= kFdStep;
      const SurfaceClosestPoint p = s.closest(xp), m = s.closest(xm);
      same_region = same_region && p.triangle == c.triangle && m.triangle == c.triangle && p.feature == c.feature &&
                    m.feature == c.feature;
      dn_fd.col(j) = (p.normal - m.normal) / (2 * kFdStep);
      dg_fd[j] = (p.gap - m.gap) / (2 * kFdStep);
    }
    if (!same_region) continue;  // a difference across region boundaries is not a derivative
    ++seen[static_cast<int>(c.feature)];
    EXPECT_LT((dg_fd - c.gap_gradient).norm(), kFdRel * std::max(1.0, c.gap_gradient.norm()));
    EXPECT_LT((dn_fd - c.normal_gradient).norm(), kFdRel * std::max(1.0, c.normal_gradient.norm()));
  }
  // Points around a sphere fall in every kind of region.
  EXPECT_GT(seen[0], 10);
  EXPECT_GT(seen[1], 5);
  EXPECT_GT(seen[2], 0);
}

TEST(TriangleSurface, SmoothedNormalIsContinuousAcrossFacetEdges) {
  const TriangleSurface s = uv_sphere(2.0, 6, 10);
  // Walk along a path outside the (convex) surface, across many facets: there the
  // closest point moves continuously.
  double worst_smooth = 0.0, worst_facet = 0.0;
  SurfaceClosestPoint prev = s.closest(2.3 * Vec3(1.0, -1.0, 0.3).normalized());
  const int n = 4000;
  for (int i = 1; i <= n; ++i) {
    const double t = double(i) / n;
    const Vec3 x = 2.3 * Vec3(std::cos(1.2 * t), -1.0 + 2.0 * t, 0.3 + 0.4 * t).normalized();
    const SurfaceClosestPoint c = s.closest(x);
    worst_smooth = std::max(worst_smooth, (c.normal - prev.normal).norm());
    worst_facet = std::max(worst_facet, (c.facet_normal - prev.facet_normal).norm());
    prev = c;
  }
  EXPECT_LT(worst_smooth, 5e-3);  // steps of ~1e-3 mm along the path
  EXPECT_GT(worst_facet, 0.1);    // facet normals jump by the facet angle (~36 degrees)
}

TEST(TriangleSurface, PointsBeyondAFreeEdgeAreNotInFront) {
  Points3 v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  const TriangleSurface s(v, {{0, 1, 2}, {0, 2, 3}});
  EXPECT_TRUE(s.closest(Vec3(0.5, 0.5, 0.2)).in_front);
  EXPECT_TRUE(s.closest(Vec3(0.5, 0.5, -0.2)).in_front);
  EXPECT_TRUE(s.closest(Vec3(1.05, 0.5, 0.2)).in_front);  // just past the edge, mostly above it
  EXPECT_FALSE(s.closest(Vec3(1.5, 0.5, 0.1)).in_front);  // well beside the edge
  EXPECT_FALSE(s.closest(Vec3(1.5, 1.5, 0.0)).in_front);  // beside a corner
  const SurfaceClosestPoint c = s.closest(Vec3(0.25, 0.5, -0.2));
  EXPECT_NEAR(c.gap, -0.2, test::kRoundoff);
  EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), test::kRoundoff);
}

TEST(TriangleSurface, RejectsBadInput) {
  Points3 v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  EXPECT_THROW(TriangleSurface(v, {{0, 1, 2}}), InputError);  // collinear
  EXPECT_THROW(TriangleSurface(v, {{0, 1, 5}}), InputError);  // index
  EXPECT_THROW(TriangleSurface(v, {}), InputError);
}

}  // namespace
}  // namespace sf::mesh
