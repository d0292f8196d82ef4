#include "gsa/measured_region.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>

#include <algorithm>
#include <cmath>

#include "common/fe/surface_field.hpp"

namespace sf::gsa {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_2<Kernel>;
using FaceBase = CGAL::Triangulation_face_base_with_info_2<bool, Kernel>;  // info: kept (not a sliver)
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

constexpr double kSliverRatio = 2.5;  // longest edge over the median edge (as gsa/triangles.cpp)

}  // namespace

std::vector<bool> measured_cells(const AnalysisResult& r, int subdiv) {
  const mesh::SurfaceMesh& mesh = r.mesh;
  const Index ne = mesh.n_elements();
  std::vector<bool> out(static_cast<std::size_t>(ne * subdiv * subdiv), true);
  if (ne == 0 || r.undeformed_parameters.rows() != mesh.n_dofs() || !mesh.has_topology()) return out;
  // Elements to test: those with a free edge. Marks of the triangulation: theirs and
  // their neighbours' (enough for the triangles over the tested elements).
  std::vector<char> tested(static_cast<std::size_t>(ne), 0), near(static_cast<std::size_t>(ne), 0);
  for (Index e = 0; e < ne; ++e)
    for (int edge = 0; edge < 4; ++edge)
      if (mesh.neighbour(e, edge).element < 0 && !mesh::SurfaceMesh::is_degenerate_edge(mesh.element(e), edge))
        tested[static_cast<std::size_t>(e)] = 1;
  for (Index e = 0; e < ne; ++e) {
    if (!tested[static_cast<std::size_t>(e)]) continue;
    near[static_cast<std::size_t>(e)] = 1;
    for (int edge = 0; edge < 4; ++edge)
      if (const Index nb = mesh.neighbour(e, edge).element; nb >= 0) near[static_cast<std::size_t>(nb)] = 1;
  }
  const fe::SurfaceField fu(mesh, r.undeformed_parameters);
  auto in_plane = [&](Index e, const Vec2& xi) {
    const Vec3 d = fu.evaluate3(e, xi, basis::kValues).x - r.centroid;
    return Kernel::Point_2(d.dot(r.axis1), d.dot(r.axis2));
  };
  std::vector<Kernel::Point_2> pts;
  for (const PointResult& p : r.points)
    if (p.element >= 0 && p.element < ne && near[static_cast<std::size_t>(p.element)])
      pts.push_back(in_plane(p.element, p.xi));
  if (pts.size() < 3) return out;
  Delaunay dt(pts.begin(), pts.end());
  if (dt.dimension() < 2) return out;
  auto longest = [](Delaunay::Face_handle f) {
    double l = 0.0;
    for (int k = 0; k < 3; ++k)
      l = std::max(l, CGAL::to_double(CGAL::squared_distance(f->vertex(k)->point(), f->vertex((k + 1) % 3)->point())));
    return std::sqrt(l);
  };
  std::vector<double> edges;
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e)
    edges.push_back(std::sqrt(CGAL::to_double(dt.segment(*e).squared_length())));
  std::nth_element(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2), edges.end());
  const double limit = kSliverRatio * edges[edges.size() / 2];
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) f->info() = longest(f) <= limit;
  Delaunay::Face_handle hint;
  for (Index e = 0; e < ne; ++e) {
    if (!tested[static_cast<std::size_t>(e)]) continue;
    for (int j = 0; j < subdiv; ++j)
      for (int i = 0; i < subdiv; ++i) {
        const Delaunay::Face_handle f = dt.locate(in_plane(e, Vec2((i + 0.5) / subdiv, (j + 0.5) / subdiv)), hint);
        const bool inside = f != nullptr && !dt.is_infinite(f) && f->info();
        if (f != nullptr) hint = f;
        out[static_cast<std::size_t>((e * subdiv + j) * subdiv + i)] = inside;
      }
  }
  return out;
}

}  // namespace sf::gsa
