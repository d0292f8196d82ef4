// Property tests of bicubic Hermite surface meshes (common/mesh/surface_mesh.hpp),
// evaluated through fe::SurfaceField: generator counts and topology, exact flat
// geometry, C1 continuity across shared edges evaluated from both sides (and its
// loss with inconsistent scale factors), arc-length scale factors, and collapsed
// apex elements of the disk mesh.

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // 2x2 metric inverse

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/fe/surface_field.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "common/quadrature/gauss.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::mesh {
namespace {

using fe::SurfaceField;
using test::kContinuity;
using test::kDetectable;
using test::kGeometry;
using test::kNormal;
using test::kRoundoff;

constexpr double kPi = 3.14159265358979323846;
constexpr unsigned kAll = basis::kValues | basis::kFirst | basis::kSecond;

std::string where(Index e, const Vec2& xi) {
  std::ostringstream os;
  os << "element " << e << " at xi=(" << xi[0] << ", " << xi[1] << ")";
  return os.str();
}

struct Frame {
  Vec3 origin, a1, a2, n;
};

// A random orthonormal frame (a1, a2, n = a1 x a2) and origin.
Frame random_frame(std::mt19937& rng) {
  std::normal_distribution<double> g;
  const Vec3 u(g(rng), g(rng), g(rng)), v(g(rng), g(rng), g(rng));
  Frame f;
  f.a1 = u.normalized();
  f.a2 = (v - v.dot(f.a1) * f.a1).normalized();
  f.n = f.a1.cross(f.a2);
  f.origin = 3.0 * Vec3(g(rng), g(rng), g(rng));
  return f;
}

MatX random_parameters(Index rows, Index cols, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX m(rows, cols);
  for (Index i = 0; i < rows; ++i)
    for (Index j = 0; j < cols; ++j) m(i, j) = u(rng);
  return m;
}

Vec3 unit_normal(const Mat32& dx) { return dx.col(0).cross(dx.col(1)).normalized(); }

// Surface gradient of each component: grad u = sum_ab G^ab u,a g_b; 3 x n_components.
MatX surface_gradient(const Mat32& dx, const MatX& du) {
  const Mat2 g = dx.transpose() * dx;
  return dx * g.inverse() * du.transpose();
}

// Local edge conventions: edges 0 and 2 run along xi1, edges 1 and 3 along xi2;
// outward across-edge direction is +xi on edges 1, 2 and -xi on edges 0, 3.
int along_dir(int edge) { return (edge == 0 || edge == 2) ? 0 : 1; }
int across_dir(int edge) { return 1 - along_dir(edge); }
double outward_sign(int edge) { return (edge == 1 || edge == 2) ? 1.0 : -1.0; }

// Largest mismatch over all interior edges of a field evaluated from both sides.
struct Jump {
  double size = 0.0;
  std::string at = "nowhere";
  void update(double s, const std::string& loc) {
    if (s > size || std::isnan(s)) {
      size = s;
      at = loc;
    }
  }
};
struct EdgeJumps {
  Jump value, along, across, gradient;
  int n_edges = 0;
};

EdgeJumps edge_jumps(const SurfaceMesh& mesh, const MatX& field) {
  const SurfaceField u(mesh, field);
  const SurfaceField x(mesh, mesh.geometry());
  EdgeJumps j;
  const double ts[] = {0.0, 0.15, 0.4, 0.5, 0.77, 1.0};
  for (Index e = 0; e < mesh.n_elements(); ++e)
    for (int edge = 0; edge < 4; ++edge) {
      const EdgeNeighbour& nb = mesh.neighbour(e, edge);
      if (nb.element < e) continue;  // boundary (-1) or visited from the other side
      ++j.n_edges;
      EXPECT_FALSE(nb.reversed) << "generators orient neighbours consistently: element " << e << " edge " << edge;
      for (double t : ts) {
        const Vec2 xa = edge_point(edge, t), xb = edge_point(nb.edge, t);
        const auto pa = u.evaluate(e, xa, kAll), pb = u.evaluate(nb.element, xb, kAll);
        std::ostringstream os;
        os << "edge " << edge << " of element " << e << " / edge " << nb.edge << " of element " << nb.element
           << " at t=" << t;
        j.value.update((pa.value - pb.value).cwiseAbs().maxCoeff(), os.str());
        j.along.update((pa.first.col(along_dir(edge)) - pb.first.col(along_dir(nb.edge))).cwiseAbs().maxCoeff(),
                       os.str());
        j.across.update((outward_sign(edge) * pa.first.col(across_dir(edge)) +
                         outward_sign(nb.edge) * pb.first.col(across_dir(nb.edge)))
                            .cwiseAbs()
                            .maxCoeff(),
                        os.str());
        if (t <= 0.0 || t >= 1.0) continue;  // keep away from collapsed apexes
        const auto ga = x.evaluate3(e, xa, basis::kFirst), gb = x.evaluate3(nb.element, xb, basis::kFirst);
        const MatX grad_a = surface_gradient(ga.dx, pa.first), grad_b = surface_gradient(gb.dx, pb.first);
        j.gradient.update((grad_a - grad_b).cwiseAbs().maxCoeff(), os.str());
      }
    }
  return j;
}

void expect_c1(const EdgeJumps& j, double tol, const std::string& what) {
  EXPECT_GT(j.n_edges, 0) << what << ": no interior edges";
  EXPECT_LT(j.value.size, tol) << what << ": value jump at " << j.value.at;
  EXPECT_LT(j.along.size, tol) << what << ": along-edge xi-derivative jump at " << j.along.at;
  EXPECT_LT(j.across.size, tol) << what << ": across-edge xi-derivative jump at " << j.across.at;
  EXPECT_LT(j.gradient.size, tol) << what << ": physical surface-gradient jump at " << j.gradient.at;
}

// ---------------------------------------------------------------------------
// Rectangle meshes

TEST(SurfaceMeshRectangle, CountsAndBoundaryEdges) {
  const int sizes[][2] = {{1, 1}, {3, 2}, {4, 5}, {1, 6}};
  for (const auto& s : sizes) {
    const int n1 = s[0], n2 = s[1];
    const SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 2.0, 1.0, n1, n2);
    const std::string tag = std::to_string(n1) + "x" + std::to_string(n2) + " mesh";
    EXPECT_EQ(m.n_nodes(), (n1 + 1) * (n2 + 1)) << tag;
    EXPECT_EQ(m.n_elements(), n1 * n2) << tag;
    EXPECT_EQ(m.n_dofs(), 4 * (n1 + 1) * (n2 + 1)) << tag;
    const auto boundary = m.boundary_edges();
    EXPECT_EQ(static_cast<int>(boundary.size()), 2 * (n1 + n2)) << tag;
    for (const auto& [e, edge] : boundary) {
      const int i = static_cast<int>(e % n1), j = static_cast<int>(e / n1);
      const bool outer =
          (edge == 0 && j == 0) || (edge == 2 && j == n2 - 1) || (edge == 3 && i == 0) || (edge == 1 && i == n1 - 1);
      EXPECT_TRUE(outer) << tag << ": boundary edge " << edge << " of element (" << i << ", " << j
                         << ") is not on the outline";
    }
    for (const auto& el : m.elements()) EXPECT_EQ(el.shape, ElementShape::kQuad) << tag;
  }
}

TEST(SurfaceMeshRectangle, NeighboursAreSymmetricAndStructured) {
  const int n1 = 4, n2 = 3;
  const SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 4.0, 3.0, n1, n2);
  int interior = 0;
  for (Index e = 0; e < m.n_elements(); ++e) {
    const int i = static_cast<int>(e % n1), j = static_cast<int>(e / n1);
    // Expected neighbour per edge: 0 below, 1 right, 2 above, 3 left.
    const Index expected[4] = {j > 0 ? e - n1 : -1, i < n1 - 1 ? e + 1 : -1, j < n2 - 1 ? e + n1 : -1,
                               i > 0 ? e - 1 : -1};
    const int opposite[4] = {2, 3, 0, 1};
    for (int edge = 0; edge < 4; ++edge) {
      const EdgeNeighbour& nb = m.neighbour(e, edge);
      EXPECT_EQ(nb.element, expected[edge]) << "element " << e << " edge " << edge;
      if (nb.element < 0) continue;
      ++interior;
      EXPECT_EQ(nb.edge, opposite[edge]) << "element " << e << " edge " << edge;
      const EdgeNeighbour& back = m.neighbour(nb.element, nb.edge);
      EXPECT_EQ(back.element, e) << "symmetry: element " << e << " edge " << edge;
      EXPECT_EQ(back.edge, edge) << "symmetry: element " << e << " edge " << edge;
      EXPECT_EQ(back.reversed, nb.reversed) << "symmetry: element " << e << " edge " << edge;
      // The two sides share the same global nodes.
      const auto la = edge_local_nodes(edge), lb = edge_local_nodes(nb.edge);
      const std::set<Index> sa{m.element(e).nodes[la[0]], m.element(e).nodes[la[1]]};
      const std::set<Index> sb{m.element(nb.element).nodes[lb[0]], m.element(nb.element).nodes[lb[1]]};
      EXPECT_EQ(sa, sb) << "shared nodes of element " << e << " edge " << edge;
    }
  }
  EXPECT_EQ(interior, 2 * ((n1 - 1) * n2 + n1 * (n2 - 1))) << "each interior edge seen from both sides";
}

TEST(SurfaceMeshRectangle, UniformMeshReproducesTheFlatPlaneExactly) {
  std::mt19937 rng(test::kSeed + 100);
  const Frame f = random_frame(rng);
  const double l1 = 3.0, l2 = 2.0;
  const int n1 = 3, n2 = 4;
  const SurfaceMesh m = make_rectangle_mesh(f.origin, f.a1, f.a2, l1, l2, n1, n2);
  const SurfaceField x(m, m.geometry());
  const double h1 = l1 / n1, h2 = l2 / n2;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Index e = 0; e < m.n_elements(); ++e) {
    const int i = static_cast<int>(e % n1), j = static_cast<int>(e / n1);
    for (int q = 0; q < 6; ++q) {
      const Vec2 xi(u(rng), u(rng));
      const auto p = x.evaluate3(e, xi, kAll);
      const Vec3 expected = f.origin + (i + xi[0]) * h1 * f.a1 + (j + xi[1]) * h2 * f.a2;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(p.x[c], expected[c], kGeometry) << "x component " << c << ", " << where(e, xi);
        EXPECT_NEAR(p.dx(c, 0), h1 * f.a1[c], kGeometry) << "x,1 component " << c << ", " << where(e, xi);
        EXPECT_NEAR(p.dx(c, 1), h2 * f.a2[c], kGeometry) << "x,2 component " << c << ", " << where(e, xi);
        for (int s = 0; s < 3; ++s)
          EXPECT_NEAR(p.d2x(c, s), 0.0, kGeometry)
              << "second derivative " << s << " component " << c << ", " << where(e, xi);
      }
      EXPECT_NEAR(unit_normal(p.dx).dot(f.n), 1.0, kNormal) << "normal a1 x a2, " << where(e, xi);
    }
  }
}

TEST(SurfaceMeshRectangle, UniformScaleFactorsAreTheElementSizes) {
  const SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 3.0, 2.0, 3, 4);
  for (Index e = 0; e < m.n_elements(); ++e)
    for (int n = 0; n < 4; ++n) {
      EXPECT_NEAR(m.element(e).scale[n][0], 1.0, kGeometry) << "S1, element " << e << " local node " << n;
      EXPECT_NEAR(m.element(e).scale[n][1], 0.5, kGeometry) << "S2, element " << e << " local node " << n;
    }
}

TEST(SurfaceMeshRectangle, RejectsBadInput) {
  const Vec3 o = Vec3::Zero(), ex = Vec3::UnitX(), ey = Vec3::UnitY();
  EXPECT_THROW(make_rectangle_mesh(o, ex, Vec3(1, 1, 0), 1, 1, 2, 2), std::invalid_argument) << "non-orthogonal";
  EXPECT_THROW(make_rectangle_mesh(o, 2 * ex, ey, 1, 1, 2, 2), std::invalid_argument) << "not unit";
  EXPECT_THROW(make_rectangle_mesh(o, ex, ey, 1, 1, 0, 2), std::invalid_argument) << "zero elements";
  EXPECT_THROW(make_rectangle_mesh(o, ex, ey, -1, 1, 2, 2), std::invalid_argument) << "negative length";
  EXPECT_THROW(make_rectangle_mesh(o, ex, ey, 1, 1, 2, 2, {0.0, 1.0}), std::invalid_argument)
      << "wrong number of breakpoints";
  EXPECT_THROW(make_rectangle_mesh(o, ex, ey, 1, 1, 2, 2, {0.0, 0.7, 0.5}), std::invalid_argument)
      << "descending breakpoints";
  EXPECT_THROW(make_disk_mesh(o, ex, ey, 1.0, 1, 2), std::invalid_argument) << "two sectors";
  EXPECT_THROW(make_disk_mesh(o, ex, ey, 0.0, 1, 8), std::invalid_argument) << "zero radius";
}

TEST(SurfaceMeshElementMap, QuadParametersAreScaledNodalParameters) {
  std::mt19937 rng(test::kSeed + 101);
  SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 4.0, 3.0, 2, 2, {0, 1, 4}, {0, 2, 3});
  const MatX field = random_parameters(m.n_dofs(), 2, rng);
  for (Index e = 0; e < m.n_elements(); ++e) {
    const Element& el = m.element(e);
    const auto ue = m.element_parameters(e, field);
    for (int n = 0; n < 4; ++n) {
      const double s1 = el.scale[n][0], s2 = el.scale[n][1];
      const double factor[4] = {1.0, s1, s2, s1 * s2};
      for (int d = 0; d < 4; ++d)
        for (int c = 0; c < 2; ++c)
          EXPECT_NEAR(ue(4 * n + d, c), factor[d] * field(SurfaceMesh::dof(el.nodes[n], d), c), kRoundoff)
              << "element " << e << " local node " << n << " parameter " << d << " component " << c;
    }
  }
}

// ---------------------------------------------------------------------------
// Graded rectangle meshes: element widths 1 and 3 (xi1), 2 and 0.5 (xi2).

const std::vector<double> kBreaks1{0.0, 1.0, 4.0};
const std::vector<double> kBreaks2{0.0, 2.0, 2.5};

SurfaceMesh graded_mesh(const Frame& f) {
  return make_rectangle_mesh(f.origin, f.a1, f.a2, 4.0, 2.5, 2, 2, kBreaks1, kBreaks2);
}

TEST(SurfaceMeshGraded, ScaleFactorsAreNodalMeansOfLineLengths) {
  std::mt19937 rng(test::kSeed + 110);
  const SurfaceMesh m = graded_mesh(random_frame(rng));
  // Per grid column i (xi1) and row j (xi2): mean length of the lines meeting there.
  const double s1[3] = {1.0, 2.0, 3.0}, s2[3] = {2.0, 1.25, 0.5};
  for (Index e = 0; e < m.n_elements(); ++e) {
    const int i = static_cast<int>(e % 2), j = static_cast<int>(e / 2);
    for (int n = 0; n < 4; ++n) {
      const int gi = i + (n & 1), gj = j + (n >> 1);
      EXPECT_NEAR(m.element(e).scale[n][0], s1[gi], kGeometry) << "S1, element " << e << " local node " << n;
      EXPECT_NEAR(m.element(e).scale[n][1], s2[gj], kGeometry) << "S2, element " << e << " local node " << n;
    }
  }
}

TEST(SurfaceMeshGraded, GeometryStaysInThePlaneAlongTheGridLines) {
  std::mt19937 rng(test::kSeed + 111);
  const Frame f = random_frame(rng);
  const SurfaceMesh m = graded_mesh(f);
  const SurfaceField x(m, m.geometry());
  const double s1[3] = {1.0, 2.0, 3.0}, s2[3] = {2.0, 1.25, 0.5};
  // In-plane coordinate along a1 of element column i: cubic Hermite through the
  // breakpoints with slopes = nodal scale factors (d/ds1 = a1 at every node).
  auto hermite = [](double t, double v0, double d0, double v1, double d1, int order) {
    const auto h = basis::cubic_hermite(t, order);
    return h[0] * v0 + h[1] * d0 + h[2] * v1 + h[3] * d1;
  };
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Index e = 0; e < m.n_elements(); ++e) {
    const int i = static_cast<int>(e % 2), j = static_cast<int>(e / 2);
    for (int q = 0; q < 8; ++q) {
      const Vec2 xi(u(rng), u(rng));
      const auto p = x.evaluate3(e, xi, basis::kValues | basis::kFirst);
      const Vec3 r = p.x - f.origin;
      EXPECT_NEAR(r.dot(f.n), 0.0, kGeometry) << "out of plane, " << where(e, xi);
      EXPECT_NEAR(p.dx.col(0).dot(f.n), 0.0, kGeometry) << "x,1 out of plane, " << where(e, xi);
      EXPECT_NEAR(p.dx.col(1).dot(f.n), 0.0, kGeometry) << "x,2 out of plane, " << where(e, xi);
      EXPECT_NEAR(p.dx.col(0).dot(f.a2), 0.0, kGeometry) << "x,1 along a1 only, " << where(e, xi);
      EXPECT_NEAR(p.dx.col(1).dot(f.a1), 0.0, kGeometry) << "x,2 along a2 only, " << where(e, xi);
      EXPECT_NEAR(r.dot(f.a1), hermite(xi[0], kBreaks1[i], s1[i], kBreaks1[i + 1], s1[i + 1], 0), kGeometry)
          << "s coordinate, " << where(e, xi);
      EXPECT_NEAR(r.dot(f.a2), hermite(xi[1], kBreaks2[j], s2[j], kBreaks2[j + 1], s2[j + 1], 0), kGeometry)
          << "t coordinate, " << where(e, xi);
      EXPECT_GT(p.dx.col(0).dot(f.a1), 0.0) << "s increases with xi1 (no fold), " << where(e, xi);
      EXPECT_GT(p.dx.col(1).dot(f.a2), 0.0) << "t increases with xi2 (no fold), " << where(e, xi);
    }
  }
}

TEST(SurfaceMeshGraded, GeometryIsC1AcrossSharedEdges) {
  std::mt19937 rng(test::kSeed + 112);
  const SurfaceMesh m = graded_mesh(random_frame(rng));
  const EdgeJumps j = edge_jumps(m, m.geometry());
  EXPECT_EQ(j.n_edges, 4);
  expect_c1(j, kContinuity, "graded geometry");
}

TEST(SurfaceMeshGraded, RandomScalarAndVectorFieldsAreC1AcrossSharedEdges) {
  std::mt19937 rng(test::kSeed + 113);
  const SurfaceMesh m = graded_mesh(random_frame(rng));
  expect_c1(edge_jumps(m, random_parameters(m.n_dofs(), 1, rng)), kContinuity, "random scalar field");
  expect_c1(edge_jumps(m, random_parameters(m.n_dofs(), 3, rng)), kContinuity, "random vector field");
}

TEST(SurfaceMeshGraded, LinearFunctionOfPositionHasTheExactSurfaceGradient) {
  // u = c . x has nodal parameters c . (geometry parameters) and surface gradient
  // P c (projection onto the plane) everywhere, on every element.
  std::mt19937 rng(test::kSeed + 114);
  const Frame f = random_frame(rng);
  const SurfaceMesh m = graded_mesh(f);
  const Vec3 c(0.3, -1.2, 0.7);
  const MatX field = m.geometry() * c;
  const SurfaceField u(m, field), x(m, m.geometry());
  const Vec3 expected = c - c.dot(f.n) * f.n;
  std::uniform_real_distribution<double> r(0.0, 1.0);
  for (Index e = 0; e < m.n_elements(); ++e)
    for (int q = 0; q < 5; ++q) {
      const Vec2 xi(r(rng), r(rng));
      const auto pu = u.evaluate(e, xi, basis::kValues | basis::kFirst);
      const auto px = x.evaluate3(e, xi, basis::kValues | basis::kFirst);
      EXPECT_NEAR(pu.value[0], c.dot(px.x), kGeometry) << "value, " << where(e, xi);
      const MatX grad = surface_gradient(px.dx, pu.first);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(grad(k, 0), expected[k], kGeometry) << "gradient " << k << ", " << where(e, xi);
    }
}

TEST(SurfaceMeshGraded, InconsistentElementScaleFactorsBreakC1) {
  // Control: the generated (nodal-consistent) factors are C1. Then element-based
  // factors (each side uses its own element width at the shared nodes) give an
  // xi-derivative jump across the edge; factors that also differ along the edge
  // break the physical gradient. The jumps must be clearly visible.
  std::mt19937 rng(test::kSeed + 115);
  SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 4.0, 1.0, 2, 1, kBreaks1);
  ASSERT_EQ(m.neighbour(0, 1).element, 1);
  const MatX field = random_parameters(m.n_dofs(), 1, rng);
  expect_c1(edge_jumps(m, field), kContinuity, "nodal-consistent factors");

  // Element-based: left element S1 = 1 at its right nodes (1, 3), right element S1 = 3 at (0, 2).
  m.element(0).scale[1][0] = m.element(0).scale[3][0] = 1.0;
  m.element(1).scale[0][0] = m.element(1).scale[2][0] = 3.0;
  const EdgeJumps element_based = edge_jumps(m, field);
  EXPECT_LT(element_based.value.size, kContinuity) << "C0 survives: " << element_based.value.at;
  EXPECT_GT(element_based.across.size, kDetectable)
      << "u,1 at xi1=1 (left) and xi1=0 (right) must differ with element-based factors";

  // Different along the edge as well: S1 = 3 at the bottom, 1.5 at the top of the right side.
  m.element(1).scale[2][0] = 1.5;
  const EdgeJumps skewed = edge_jumps(m, field);
  EXPECT_GT(skewed.across.size, kDetectable) << "xi-derivative across the edge";
  EXPECT_GT(skewed.gradient.size, kDetectable) << "physical gradient du/dx across the edge";
}

// Smallest d(s)/dxi1 over element e of a mesh along a1 (s = coordinate along a1),
// sampled along xi1 at mid-height; negative means the parameterisation folds.
double min_slope_along_a1(const SurfaceMesh& m, Index e) {
  const SurfaceField x(m, m.geometry());
  double slope = 1e300;
  for (int q = 0; q <= 200; ++q)
    slope = std::min(slope, x.evaluate3(e, Vec2(q / 200.0, 0.5), basis::kFirst).dx.col(0).x());
  return slope;
}

TEST(SurfaceMeshGraded, ModerateGradingIsFoldFreeWithExactArcLengthFactors) {
  // Two elements of widths 1 and w along a1. The nodal mean factor (1 + w)/2 at
  // the shared node keeps the narrow element monotone for w <= 7.
  for (double w : {2.0, 3.0, 6.0}) {
    const SurfaceMesh m =
        make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0 + w, 1.0, 2, 1, {0.0, 1.0, 1.0 + w});
    for (Index e = 0; e < 2; ++e)
      EXPECT_GT(min_slope_along_a1(m, e), 0.0) << "fold in element " << e << " for widths 1 and " << w;
    EXPECT_NEAR(m.element(0).scale[0][0], 1.0, kGeometry) << "S1 at the narrow end, widths 1 and " << w;
    EXPECT_NEAR(m.element(0).scale[1][0], 0.5 * (1.0 + w), kGeometry) << "S1 at the shared node, widths 1 and " << w;
    EXPECT_NEAR(m.element(1).scale[1][0], w, kGeometry) << "S1 at the wide end, widths 1 and " << w;
  }
}

// LIBRARY ISSUE (reported to the lead; disabled until fixed): make_rectangle_mesh
// with adjacent breakpoint widths in a ratio above 7 folds the narrow element.
// The nodal mean scale factor (1 + w)/2 exceeds 4x the narrow width, so
// ds/dxi1 < 0 inside it (widths 1 and 10: min ds/dxi1 = -0.57), the "exact
// arc-length parameters" of the header no longer hold (S1 at the narrow free end
// becomes 1.36 instead of 1), and the surface Jacobian vanishes inside the
// element. Either rejecting such grading (std::invalid_argument) or producing a
// fold-free mesh passes this test.
TEST(SurfaceMeshGraded, StrongGradingIsRejectedOrFoldFree) {
  for (double w : {10.0, 20.0}) {
    SurfaceMesh m;
    try {
      m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0 + w, 1.0, 2, 1, {0.0, 1.0, 1.0 + w});
    } catch (const std::invalid_argument&) {
      continue;  // rejected: acceptable
    }
    for (Index e = 0; e < 2; ++e)
      EXPECT_GT(min_slope_along_a1(m, e), 0.0) << "fold in element " << e << " for widths 1 and " << w;
    EXPECT_NEAR(m.element(0).scale[0][0], 1.0, kGeometry) << "S1 at the narrow free end, widths 1 and " << w;
  }
}

// ---------------------------------------------------------------------------
// Arc-length scale factors on a curved strip: 8 elements around a half circle of
// radius R (xi1), width 0.5 along z (xi2).

TEST(SurfaceMeshArcLength, CircularArcScaleFactorsApproachTheArcLength) {
  const double radius = 10.0, width = 0.5;
  const int n1 = 8;
  const double dtheta = kPi / n1, arc = radius * dtheta;
  // Start from a flat strip of total length 1 (factors 0.125, far from the arc length).
  SurfaceMesh m = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 1.0, width, n1, 1);
  for (int j = 0; j <= 1; ++j)
    for (int i = 0; i <= n1; ++i) {
      const Index node = static_cast<Index>(j) * (n1 + 1) + i;
      const double th = i * dtheta;
      m.geometry().row(SurfaceMesh::dof(node, kValue)) = Vec3(radius * std::cos(th), radius * std::sin(th), j * width);
      m.geometry().row(SurfaceMesh::dof(node, kD1)) = Vec3(-std::sin(th), std::cos(th), 0.0);
      m.geometry().row(SurfaceMesh::dof(node, kD2)) = Vec3::UnitZ();
      m.geometry().row(SurfaceMesh::dof(node, kD12)) = Vec3::Zero();
    }
  const int max_iterations = 20;
  const int iterations = m.compute_arc_length_scale_factors(max_iterations, 1e-10);
  // Measured: 6 iterations to 1e-10 (the error shrinks ~50x per iteration).
  EXPECT_LE(iterations, 8) << "fixed-point iteration for the arc-length factors should converge in a few steps";
  EXPECT_LT(iterations, max_iterations) << "must converge before the iteration limit";
  for (Index e = 0; e < m.n_elements(); ++e)
    for (int n = 0; n < 4; ++n) {
      EXPECT_NEAR(m.element(e).scale[n][0] / arc, 1.0, test::kArcLengthRel)
          << "S1 against the arc length, element " << e << " local node " << n;
      EXPECT_NEAR(m.element(e).scale[n][1], width, kGeometry) << "S2 (straight lines), element " << e;
    }
  // The fitted curves themselves: length by Gauss quadrature and distance from the axis.
  const SurfaceField x(m, m.geometry());
  const quadrature::Rule1D g = quadrature::gauss_legendre(8);
  for (Index e = 0; e < m.n_elements(); ++e) {
    double len = 0.0;
    for (std::size_t q = 0; q < g.points.size(); ++q)
      len += g.weights[q] * x.evaluate3(e, Vec2(g.points[q], 0.0), basis::kFirst).dx.col(0).norm();
    EXPECT_NEAR(len / arc, 1.0, test::kArcLengthRel) << "length of the xi1 line of element " << e;
    const Vec3 mid = x.evaluate3(e, Vec2(0.5, 0.5), basis::kValues).x;
    EXPECT_NEAR(std::hypot(mid[0], mid[1]) / radius, 1.0, test::kArcLengthRel) << "radius at mid-element " << e;
  }
}

// ---------------------------------------------------------------------------
// Disk meshes with collapsed elements at the centre.

struct Disk {
  Frame f;
  double radius;
  int n_rings, n_sectors;
  SurfaceMesh mesh;
};

Disk make_disk(unsigned seed, int n_rings, int n_sectors, double radius = 2.0) {
  std::mt19937 rng(seed);
  Disk d{random_frame(rng), radius, n_rings, n_sectors, SurfaceMesh()};
  d.mesh = make_disk_mesh(d.f.origin, d.f.a1, d.f.a2, radius, n_rings, n_sectors);
  return d;
}

double disk_area(const SurfaceMesh& m) {
  const SurfaceField x(m, m.geometry());
  const quadrature::TensorRule<2> rule = quadrature::gauss_2d(6, 6);
  double area = 0.0;
  for (Index e = 0; e < m.n_elements(); ++e)
    for (int q = 0; q < rule.size(); ++q) {
      const auto p = x.evaluate3(e, rule.points[q], basis::kFirst);
      area += rule.weights[q] * p.dx.col(0).cross(p.dx.col(1)).norm();
    }
  return area;
}

TEST(SurfaceMeshDisk, CountsTopologyAndCollapsedElements) {
  const std::pair<int, int> cases[] = {{1, 3}, {2, 6}, {4, 8}};
  for (const auto& [rings, sectors] : cases) {
    const Disk d = make_disk(test::kSeed + 200, rings, sectors);
    const SurfaceMesh& m = d.mesh;
    const std::string tag = std::to_string(rings) + " rings x " + std::to_string(sectors) + " sectors";
    EXPECT_EQ(m.n_nodes(), 1 + rings * sectors) << tag;
    EXPECT_EQ(m.n_elements(), rings * sectors) << tag;
    EXPECT_EQ(static_cast<int>(m.boundary_edges().size()), sectors) << tag << ": outer circle only";
    int collapsed = 0;
    for (Index e = 0; e < m.n_elements(); ++e) {
      const Element& el = m.element(e);
      if (el.shape == ElementShape::kCollapsed) {
        ++collapsed;
        EXPECT_EQ(el.nodes[0], el.nodes[1]) << tag << ": collapsed element " << e;
        EXPECT_EQ(m.neighbour(e, 0).element, -1) << tag << ": degenerate edge has no neighbour, element " << e;
        EXPECT_EQ(m.element(m.neighbour(e, 1).element).shape, ElementShape::kCollapsed)
            << tag << ": radial edge neighbour of collapsed element " << e;
      }
      for (int edge = 0; edge < 4; ++edge) {
        const EdgeNeighbour& nb = m.neighbour(e, edge);
        if (nb.element < 0) continue;
        const EdgeNeighbour& back = m.neighbour(nb.element, nb.edge);
        EXPECT_EQ(back.element, e) << tag << ": symmetry, element " << e << " edge " << edge;
        EXPECT_EQ(back.edge, edge) << tag << ": symmetry, element " << e << " edge " << edge;
      }
    }
    EXPECT_EQ(collapsed, sectors) << tag;
    for (const auto& [e, edge] : m.boundary_edges())
      EXPECT_EQ(edge, 2) << tag << ": boundary edge of element " << e << " is on the outer ring (xi2 = 1)";
  }
}

TEST(SurfaceMeshDisk, ApexIsOnePointWithVanishingXi1Derivative) {
  const Disk d = make_disk(test::kSeed + 201, 4, 8);
  const SurfaceField x(d.mesh, d.mesh.geometry());
  for (Index e = 0; e < d.mesh.n_elements(); ++e) {
    if (d.mesh.element(e).shape != ElementShape::kCollapsed) continue;
    for (int q = 0; q <= 10; ++q) {
      const Vec2 xi(q / 10.0, 0.0);
      const auto p = x.evaluate3(e, xi, kAll);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(p.x[c], d.f.origin[c], kGeometry) << "apex position component " << c << ", " << where(e, xi);
        EXPECT_NEAR(p.dx(c, 0), 0.0, kGeometry) << "x,1 component " << c << ", " << where(e, xi);
        EXPECT_NEAR(p.d2x(c, 0), 0.0, kGeometry) << "x,11 component " << c << ", " << where(e, xi);
      }
    }
  }
}

TEST(SurfaceMeshDisk, ApexRadialTangentsPointAlongTheSectorEdges) {
  const int sectors = 8;
  const Disk d = make_disk(test::kSeed + 202, 4, sectors);
  const SurfaceField x(d.mesh, d.mesh.geometry());
  const double dtheta = 2 * kPi / sectors;
  for (Index e = 0; e < sectors; ++e) {
    ASSERT_EQ(d.mesh.element(e).shape, ElementShape::kCollapsed) << "collapsed elements come first";
    for (int side = 0; side < 2; ++side) {
      const double th = (e + side) * dtheta;
      const Vec3 radial = std::cos(th) * d.f.a1 + std::sin(th) * d.f.a2;
      const Vec2 xi(side, 0.0);
      const Vec3 t = x.evaluate3(e, xi, basis::kFirst).dx.col(1);
      ASSERT_GT(t.norm(), kDetectable) << "x,2 at the apex, " << where(e, xi);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(t.normalized()[c], radial[c], kNormal)
            << "direction of x,2 (theta=" << th << ") component " << c << ", " << where(e, xi);
      // Its length is the apex radial scale factor: the (straight) radial lines have length R / n_rings.
      EXPECT_NEAR(t.norm(), d.radius / d.n_rings, kGeometry) << "|x,2| at the apex, " << where(e, xi);
    }
  }
}

TEST(SurfaceMeshDisk, ApexTangentPlaneIsTheDiskPlane) {
  const Disk d = make_disk(test::kSeed + 203, 3, 7);
  const SurfaceField x(d.mesh, d.mesh.geometry());
  for (Index e = 0; e < d.n_sectors; ++e)
    for (int q = 0; q <= 10; ++q) {
      const Vec2 xi(q / 10.0, 0.0);
      const auto p = x.evaluate3(e, xi, kAll);
      EXPECT_GT(p.dx.col(1).norm(), kDetectable) << "x,2 nonzero at the apex, " << where(e, xi);
      EXPECT_NEAR(p.dx.col(1).normalized().dot(d.f.n), 0.0, kNormal) << "x,2 in the disk plane, " << where(e, xi);
      EXPECT_NEAR(p.d2x.col(1).dot(d.f.n), 0.0, kGeometry) << "x,12 in the disk plane, " << where(e, xi);
    }
}

TEST(SurfaceMeshDisk, NormalIsContinuousAcrossRadialEdgesNearTheApex) {
  const Disk d = make_disk(test::kSeed + 204, 4, 8);
  const SurfaceField x(d.mesh, d.mesh.geometry());
  Vec3 reference = Vec3::Zero();
  for (Index e = 0; e < d.n_sectors; ++e) {
    const EdgeNeighbour& nb = d.mesh.neighbour(e, 1);  // xi1 = 1 side
    ASSERT_GE(nb.element, 0);
    ASSERT_EQ(nb.edge, 3);
    for (double xi2 : {1e-3, 1e-2, 0.1, 0.5, 1.0}) {
      const Vec2 xa(1.0, xi2), xb(0.0, xi2);
      const Vec3 na = unit_normal(x.evaluate3(e, xa, basis::kFirst).dx);
      const Vec3 nb3 = unit_normal(x.evaluate3(nb.element, xb, basis::kFirst).dx);
      ASSERT_TRUE(na.allFinite()) << "normal is NaN, " << where(e, xa);
      ASSERT_TRUE(nb3.allFinite()) << "normal is NaN, " << where(nb.element, xb);
      if (reference.isZero()) reference = na;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(na[c], nb3[c], kNormal) << "normal component " << c << " across the radial edge, " << where(e, xa)
                                            << " vs " << where(nb.element, xb);
        EXPECT_NEAR(na[c], reference[c], kNormal) << "one orientation for the whole disk, " << where(e, xa);
      }
      EXPECT_NEAR(std::abs(na.dot(d.f.n)), 1.0, kNormal) << "normal is +-a1 x a2, " << where(e, xa);
    }
  }
  // Quads share the orientation of the collapsed elements.
  for (Index e = d.n_sectors; e < d.mesh.n_elements(); ++e) {
    const Vec2 xi(0.5, 0.5);
    const Vec3 n = unit_normal(x.evaluate3(e, xi, basis::kFirst).dx);
    EXPECT_NEAR(n.dot(reference), 1.0, kNormal) << "orientation, " << where(e, xi);
  }
}

TEST(SurfaceMeshDisk, CurvedApexKeepsTangentPlaneContinuity) {
  // Random nodal parameters everywhere (a curved, twisted surface): every radial
  // tangent at the apex lies in span(D1, D2), the normal tends to +-D1 x D2 from
  // every sector, and normals agree across shared radial edges.
  Disk d = make_disk(test::kSeed + 205, 3, 6);
  std::mt19937 rng(test::kSeed + 206);
  d.mesh.geometry() = random_parameters(d.mesh.n_dofs(), 3, rng);
  const Index apex = d.mesh.element(0).nodes[0];
  const Vec3 d1 = d.mesh.geometry().row(SurfaceMesh::dof(apex, kD1)).transpose();
  const Vec3 d2 = d.mesh.geometry().row(SurfaceMesh::dof(apex, kD2)).transpose();
  const Vec3 m = d1.cross(d2).normalized();
  const SurfaceField x(d.mesh, d.mesh.geometry());
  double sign = 0.0;
  for (Index e = 0; e < d.n_sectors; ++e) {
    for (int q = 0; q <= 10; ++q) {
      const Vec2 xi(q / 10.0, 0.0);
      const auto p = x.evaluate3(e, xi, kAll);
      EXPECT_NEAR(p.dx.col(1).dot(m), 0.0, kGeometry) << "x,2 in span(D1, D2), " << where(e, xi);
      EXPECT_NEAR(p.d2x.col(1).dot(m), 0.0, kGeometry) << "x,12 in span(D1, D2), " << where(e, xi);
      const Vec2 off(q / 10.0, 1e-6);
      const Vec3 n = unit_normal(x.evaluate3(e, off, basis::kFirst).dx);
      ASSERT_TRUE(n.allFinite()) << "normal is NaN, " << where(e, off);
      if (sign == 0.0) sign = n.dot(m) > 0 ? 1.0 : -1.0;
      EXPECT_LT((n - sign * m).norm(), test::kApexNormalLimit) << "normal next to the apex, " << where(e, off);
    }
    const EdgeNeighbour& nb = d.mesh.neighbour(e, 1);
    for (double xi2 : {1e-3, 0.3, 0.8}) {
      const Vec3 na = unit_normal(x.evaluate3(e, Vec2(1.0, xi2), basis::kFirst).dx);
      const Vec3 nb3 = unit_normal(x.evaluate3(nb.element, Vec2(0.0, xi2), basis::kFirst).dx);
      EXPECT_LT((na - nb3).norm(), kNormal)
          << "normal across the radial edge of elements " << e << " and " << nb.element << " at xi2=" << xi2;
    }
  }
}

TEST(SurfaceMeshDisk, GeometryAndRandomFieldsAreC1AcrossEveryEdge) {
  Disk d = make_disk(test::kSeed + 207, 3, 8);
  std::mt19937 rng(test::kSeed + 208);
  expect_c1(edge_jumps(d.mesh, d.mesh.geometry()), kContinuity, "disk geometry");
  expect_c1(edge_jumps(d.mesh, random_parameters(d.mesh.n_dofs(), 1, rng)), kContinuity, "random scalar on disk");
}

TEST(SurfaceMeshDisk, ScaleFactorsAreNodallyConsistent) {
  const Disk d = make_disk(test::kSeed + 209, 3, 8);
  const SurfaceMesh& m = d.mesh;
  // Per (node, direction): every element using that node has the same factor.
  // The apex xi1 factor is not used (x,1 = 0 there) and is skipped.
  std::vector<std::array<double, 2>> seen(m.n_nodes(), {{-1.0, -1.0}});
  for (Index e = 0; e < m.n_elements(); ++e)
    for (int n = 0; n < 4; ++n)
      for (int dir = 0; dir < 2; ++dir) {
        const Element& el = m.element(e);
        if (el.shape == ElementShape::kCollapsed && n < 2 && dir == 0) continue;
        double& s = seen[el.nodes[n]][dir];
        if (s < 0) s = el.scale[n][dir];
        EXPECT_NEAR(el.scale[n][dir], s, kGeometry)
            << "S" << dir + 1 << " at node " << el.nodes[n] << ", element " << e << " local node " << n;
        EXPECT_GT(el.scale[n][dir], 0.0);
      }
}

TEST(SurfaceMeshDisk, AreaApproachesPiRSquaredAtFourthOrderInSectors) {
  const double radius = 2.0, exact = kPi * radius * radius;
  const double err8 = std::abs(disk_area(make_disk(test::kSeed + 210, 4, 8, radius).mesh) / exact - 1.0);
  const double err16 = std::abs(disk_area(make_disk(test::kSeed + 211, 4, 16, radius).mesh) / exact - 1.0);
  const double err32 = std::abs(disk_area(make_disk(test::kSeed + 212, 4, 32, radius).mesh) / exact - 1.0);
  EXPECT_LT(err8, test::kDiskAreaRel) << "relative area error, 8 sectors x 4 rings";
  const double factor = std::pow(2.0, test::kDiskAreaOrder);
  EXPECT_LT(err16, err8 / factor) << "16 sectors must beat 8 at fourth order (errors " << err8 << ", " << err16 << ")";
  EXPECT_LT(err32, err16 / factor) << "32 sectors must beat 16 at fourth order (errors " << err16 << ", " << err32
                                   << ")";
}

TEST(SurfaceMeshDisk, ApexCrossDerivativeDofIsTheOnlyUnusedDof) {
  const Disk d = make_disk(test::kSeed + 213, 2, 5);
  const auto used = d.mesh.used_dofs();
  ASSERT_EQ(static_cast<Index>(used.size()), d.mesh.n_dofs());
  const Index apex = d.mesh.element(0).nodes[0];
  for (Index k = 0; k < d.mesh.n_dofs(); ++k) {
    const bool expected = k != SurfaceMesh::dof(apex, kD12);
    EXPECT_EQ(used[k], expected) << "dof " << k << " (node " << k / 4 << ", parameter " << k % 4 << ")";
  }
  // A rectangle uses everything.
  const SurfaceMesh r = make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1, 1, 2, 2);
  const auto used_r = r.used_dofs();
  for (Index k = 0; k < r.n_dofs(); ++k) EXPECT_TRUE(used_r[k]) << "rectangle dof " << k;
}

TEST(SurfaceMeshDisk, CollapsedElementMapFollowsTheApexFormula) {
  // u_e[4k+1] = 0, u_e[4k+2] = S2 (cos th D1 + sin th D2),
  // u_e[4k+3] = S2 phi (-sin th D1 + cos th D2) for apex local nodes k = 0, 1.
  Disk d = make_disk(test::kSeed + 214, 2, 6);
  std::mt19937 rng(test::kSeed + 215);
  const MatX field = random_parameters(d.mesh.n_dofs(), 2, rng);
  for (Index e = 0; e < d.n_sectors; ++e) {
    const Element& el = d.mesh.element(e);
    const auto ue = d.mesh.element_parameters(e, field);
    const Index apex = el.nodes[0];
    const Eigen::RowVectorXd d1 = field.row(SurfaceMesh::dof(apex, kD1)), d2 = field.row(SurfaceMesh::dof(apex, kD2));
    const double phi = el.apex_angle[1] - el.apex_angle[0];
    EXPECT_NEAR(phi, 2 * kPi / d.n_sectors, kRoundoff) << "sector angle of element " << e;
    for (int k = 0; k < 2; ++k) {
      const double th = el.apex_angle[k], s2 = el.scale[k][1];
      const Eigen::RowVectorXd e0 = field.row(SurfaceMesh::dof(apex, kValue));
      const Eigen::RowVectorXd e2 = s2 * (std::cos(th) * d1 + std::sin(th) * d2);
      const Eigen::RowVectorXd e3 = s2 * phi * (-std::sin(th) * d1 + std::cos(th) * d2);
      for (int c = 0; c < 2; ++c) {
        EXPECT_NEAR(ue(4 * k + 0, c), e0[c], kRoundoff) << "element " << e << " apex node " << k << " value";
        EXPECT_NEAR(ue(4 * k + 1, c), 0.0, kRoundoff) << "element " << e << " apex node " << k << " d/dxi1";
        EXPECT_NEAR(ue(4 * k + 2, c), e2[c], kRoundoff) << "element " << e << " apex node " << k << " d/dxi2";
        EXPECT_NEAR(ue(4 * k + 3, c), e3[c], kRoundoff) << "element " << e << " apex node " << k << " d2/dxi1dxi2";
      }
    }
  }
}

}  // namespace
}  // namespace sf::mesh
