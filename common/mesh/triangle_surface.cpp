#include "common/mesh/triangle_surface.hpp"

// CGAL stays in this translation unit (header-only, slow to compile, private link).
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"

namespace sf::mesh {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalPoint = Kernel::Point_3;
using CgalTriangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<CgalTriangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// cos 60 degrees: beyond a free edge when x - p leaves +-n by more than this angle.
constexpr double kFrontCos = 0.5;

// Closest point of triangle (a, b, c) to x, with the region it lies in (Ericson,
// Real-Time Collision Detection, 2005, section 5.1.5). edge: 0 = ab, 1 = bc, 2 = ca;
// vertex 0, 1, 2 = a, b, c.
struct TrianglePoint {
  Vec3 b = Vec3::Zero();  // barycentric
  SurfaceClosestPoint::Feature feature = SurfaceClosestPoint::Feature::kFace;
  int which = -1;  // edge or vertex index
};

TrianglePoint closest_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  using F = SurfaceClosestPoint::Feature;
  const Vec3 ab = b - a, ac = c - a, ap = x - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {Vec3(1, 0, 0), F::kVertex, 0};
  const Vec3 bp = x - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {Vec3(0, 1, 0), F::kVertex, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {Vec3(1 - v, v, 0), F::kEdge, 0};
  }
  const Vec3 cp = x - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {Vec3(0, 0, 1), F::kVertex, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {Vec3(1 - w, 0, w), F::kEdge, 2};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {Vec3(0, 1 - w, w), F::kEdge, 1};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {Vec3(1 - v - w, v, w), F::kFace, -1};
}

}  // namespace

struct TriangleSurface::Impl {
  Points3 vertices;
  std::vector<std::array<Index, 3>> triangles;
  Points3 vertex_normals;
  std::vector<CgalTriangle> cgal_triangles;
  std::vector<std::array<bool, 3>> free_edge;  // per triangle: edge ab, bc, ca on the boundary
  std::vector<bool> free_vertex;               // on a boundary edge
  Tree tree;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();

  Vec3 vertex(Index v) const { return vertices.row(v).transpose(); }
};

TriangleSurface::TriangleSurface(Points3 vertices, std::vector<std::array<Index, 3>> triangles) {
  auto impl = std::make_shared<Impl>();
  const Index nv = vertices.rows();
  if (triangles.empty() || nv < 3) throw InputError("triangle surface: expected at least one triangle");
  for (Index v = 0; v < nv; ++v)
    if (!vertices.row(v).allFinite())
      throw InputError("triangle surface: vertex " + std::to_string(v) + " is not finite");
  impl->vertices = std::move(vertices);
  impl->triangles = std::move(triangles);
  const std::size_t nt = impl->triangles.size();
  impl->vertex_normals = Points3::Zero(nv, 3);
  std::map<std::pair<Index, Index>, int> edge_count;
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = impl->triangles[t];
    for (int i = 0; i < 3; ++i)
      if (tri[i] < 0 || tri[i] >= nv)
        throw InputError("triangle surface: triangle " + std::to_string(t) + " has vertex index " +
                         std::to_string(tri[i]) + " outside 0.." + std::to_string(nv - 1));
    const Vec3 a = impl->vertex(tri[0]), b = impl->vertex(tri[1]), c = impl->vertex(tri[2]);
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.norm() > 0.0)) throw InputError("triangle surface: triangle " + std::to_string(t) + " has zero area");
    const Vec3 un = n.normalized();
    // Angle-weighted vertex normals.
    const std::array<Vec3, 3> p = {a, b, c};
    for (int i = 0; i < 3; ++i) {
      const Vec3 e1 = (p[(i + 1) % 3] - p[i]).normalized(), e2 = (p[(i + 2) % 3] - p[i]).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      impl->vertex_normals.row(tri[i]) += angle * un.transpose();
    }
    for (int i = 0; i < 3; ++i) {
      const Index u = tri[i], w = tri[(i + 1) % 3];
      ++edge_count[{std::min(u, w), std::max(u, w)}];
    }
    impl->cgal_triangles.emplace_back(CgalPoint(a.x(), a.y(), a.z()), CgalPoint(b.x(), b.y(), b.z()),
                                      CgalPoint(c.x(), c.y(), c.z()));
  }
  for (Index v = 0; v < nv; ++v) {
    const double len = impl->vertex_normals.row(v).norm();
    if (len > 0.0) impl->vertex_normals.row(v) /= len;
  }
  impl->free_vertex.assign(static_cast<std::size_t>(nv), false);
  impl->free_edge.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = impl->triangles[t];
    for (int i = 0; i < 3; ++i) {
      const Index u = tri[i], w = tri[(i + 1) % 3];
      const bool free = edge_count[{std::min(u, w), std::max(u, w)}] == 1;
      impl->free_edge[t][i] = free;
      if (free) impl->free_vertex[static_cast<std::size_t>(u)] = impl->free_vertex[static_cast<std::size_t>(w)] = true;
    }
  }
  impl->lo = impl->vertices.colwise().minCoeff().transpose();
  impl->hi = impl->vertices.colwise().maxCoeff().transpose();
  impl->tree.insert(impl->cgal_triangles.begin(), impl->cgal_triangles.end());
  impl->tree.build();
  impl->tree.accelerate_distance_queries();
  impl_ = std::move(impl);
}

SurfaceClosestPoint TriangleSurface::closest(const Vec3& x) const {
  using F = SurfaceClosestPoint::Feature;
  const Impl& m = *impl_;
  SurfaceClosestPoint out;
  const auto hit = m.tree.closest_point_and_primitive(CgalPoint(x.x(), x.y(), x.z()));
  const Index t = static_cast<Index>(hit.second - m.cgal_triangles.begin());
  const auto& tri = m.triangles[static_cast<std::size_t>(t)];
  const std::array<Vec3, 3> v = {m.vertex(tri[0]), m.vertex(tri[1]), m.vertex(tri[2])};
  const TrianglePoint tp = closest_on_triangle(x, v[0], v[1], v[2]);
  out.triangle = t;
  out.feature = tp.feature;
  out.barycentric = tp.b;
  out.point = tp.b[0] * v[0] + tp.b[1] * v[1] + tp.b[2] * v[2];
  const Vec3 cross = (v[1] - v[0]).cross(v[2] - v[0]);
  const double two_area = cross.norm();
  const Vec3 nf = cross / two_area;
  out.facet_normal = nf;
  std::array<Vec3, 3> vn;
  for (int i = 0; i < 3; ++i) vn[i] = m.vertex_normals.row(tri[i]).transpose();
  const Vec3 sum = tp.b[0] * vn[0] + tp.b[1] * vn[1] + tp.b[2] * vn[2];
  const double len = sum.norm();
  out.normal = len > 0.0 ? Vec3(sum / len) : nf;
  const Vec3 d = x - out.point;
  out.distance = d.norm();
  out.gap = d.dot(out.normal);

  // dp/dx in the region, then db/dx = (db/dp) dp/dx.
  Mat3 dp = Mat3::Zero();
  if (tp.feature == F::kFace) {
    dp = Mat3::Identity() - nf * nf.transpose();
  } else if (tp.feature == F::kEdge) {
    const Vec3 e = (v[(tp.which + 1) % 3] - v[tp.which]).normalized();
    dp = e * e.transpose();
  }
  // Barycentric gradients in the facet plane: grad b_i = n_f x (v_{i+2} - v_{i+1}) / (2A).
  Eigen::Matrix3d db;  // row i = d b_i / dx
  for (int i = 0; i < 3; ++i) {
    const Vec3 g = nf.cross(v[(i + 2) % 3] - v[(i + 1) % 3]) / two_area;
    db.row(i) = g.transpose() * dp;
  }
  if (len > 0.0) {
    Mat3 dm = Mat3::Zero();  // d m / dx
    for (int i = 0; i < 3; ++i) dm += vn[i] * db.row(i);
    out.normal_gradient = (Mat3::Identity() - out.normal * out.normal.transpose()) * dm / len;
  }
  out.gap_gradient = ((Mat3::Identity() - dp).transpose() * out.normal + out.normal_gradient.transpose() * d);

  // Beyond a boundary edge or vertex of an open surface: no contact.
  bool boundary = false;
  if (tp.feature == F::kEdge) boundary = m.free_edge[static_cast<std::size_t>(t)][static_cast<std::size_t>(tp.which)];
  if (tp.feature == F::kVertex)
    boundary = m.free_vertex[static_cast<std::size_t>(tri[static_cast<std::size_t>(tp.which)])];
  if (boundary && out.distance > 0.0) out.in_front = std::abs(out.gap) >= kFrontCos * out.distance;
  return out;
}

const Points3& TriangleSurface::vertices() const { return impl_->vertices; }
const std::vector<std::array<Index, 3>>& TriangleSurface::triangles() const { return impl_->triangles; }
const Points3& TriangleSurface::vertex_normals() const { return impl_->vertex_normals; }
Index TriangleSurface::n_triangles() const { return static_cast<Index>(impl_->triangles.size()); }
Vec3 TriangleSurface::lower() const { return impl_->lo; }
Vec3 TriangleSurface::upper() const { return impl_->hi; }

}  // namespace sf::mesh
