#include "common/mesh/surface_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/quadrature/gauss.hpp"

namespace sf::mesh {

std::array<int, 2> edge_local_nodes(int edge) {
  switch (edge) {
    case 0:
      return {0, 1};
    case 1:
      return {1, 3};
    case 2:
      return {2, 3};
    default:
      return {0, 2};
  }
}

Vec2 edge_point(int edge, double t) {
  switch (edge) {
    case 0:
      return {t, 0.0};
    case 1:
      return {1.0, t};
    case 2:
      return {t, 1.0};
    default:
      return {0.0, t};
  }
}

Index SurfaceMesh::add_node() {
  const Index id = n_nodes_++;
  geometry_.conservativeResize(n_dofs(), 3);
  geometry_.bottomRows(kParamsPerNode).setZero();
  return id;
}

Index SurfaceMesh::add_nodes(Index count) {
  const Index first = n_nodes_;
  n_nodes_ += count;
  geometry_.conservativeResize(n_dofs(), 3);
  geometry_.bottomRows(kParamsPerNode * count).setZero();
  return first;
}

Index SurfaceMesh::add_element(const Element& element) {
  for (Index n : element.nodes)
    if (n < 0 || n >= n_nodes_) throw std::invalid_argument("SurfaceMesh::add_element: node index out of range");
  if (element.shape == ElementShape::kCollapsed && element.nodes[0] != element.nodes[1])
    throw std::invalid_argument("SurfaceMesh::add_element: collapsed element needs nodes[0] == nodes[1]");
  elements_.push_back(element);
  return n_elements() - 1;
}

ElementMap SurfaceMesh::element_map(Index e) const {
  const Element& el = elements_[e];
  ElementMap map;
  auto set1 = [&](int k, Index d, double c) {
    map.terms[k][0] = {d, c};
    map.n_terms[k] = 1;
  };
  for (int n = 0; n < 4; ++n) {
    const Index node = el.nodes[n];
    const double s1 = el.scale[n][0], s2 = el.scale[n][1];
    const bool apex = el.shape == ElementShape::kCollapsed && n < 2;
    if (!apex) {
      set1(4 * n + 0, dof(node, kValue), 1.0);
      set1(4 * n + 1, dof(node, kD1), s1);
      set1(4 * n + 2, dof(node, kD2), s2);
      set1(4 * n + 3, dof(node, kD12), s1 * s2);
      continue;
    }
    const double th = el.apex_angle[n];
    const double phi = el.apex_angle[1] - el.apex_angle[0];
    const double c = std::cos(th), s = std::sin(th);
    set1(4 * n + 0, dof(node, kValue), 1.0);
    map.n_terms[4 * n + 1] = 0;  // x,1 = 0 on the degenerate edge
    map.terms[4 * n + 2][0] = {dof(node, kD1), s2 * c};
    map.terms[4 * n + 2][1] = {dof(node, kD2), s2 * s};
    map.n_terms[4 * n + 2] = 2;
    map.terms[4 * n + 3][0] = {dof(node, kD1), -s2 * phi * s};
    map.terms[4 * n + 3][1] = {dof(node, kD2), s2 * phi * c};
    map.n_terms[4 * n + 3] = 2;
  }
  return map;
}

Eigen::Matrix<double, kElementParams, Eigen::Dynamic> SurfaceMesh::element_parameters(
    Index e, const Eigen::Ref<const MatX>& field) const {
  SF_ASSERT(field.rows() == n_dofs(), "field must have n_dofs rows");
  const ElementMap map = element_map(e);
  Eigen::Matrix<double, kElementParams, Eigen::Dynamic> u(kElementParams, field.cols());
  u.setZero();
  for (int k = 0; k < kElementParams; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t) u.row(k) += map.terms[k][t].coef * field.row(map.terms[k][t].dof);
  return u;
}

void SurfaceMesh::build_topology() {
  neighbours_.assign(4 * elements_.size(), EdgeNeighbour{});
  // Key: sorted global node pair of a non-degenerate edge.
  std::map<std::pair<Index, Index>, std::pair<Index, int>> open;
  for (Index e = 0; e < n_elements(); ++e) {
    const Element& el = elements_[e];
    for (int edge = 0; edge < 4; ++edge) {
      if (is_degenerate_edge(el, edge)) continue;
      const auto ln = edge_local_nodes(edge);
      const Index a = el.nodes[ln[0]], b = el.nodes[ln[1]];
      const auto key = std::minmax(a, b);
      auto it = open.find(key);
      if (it == open.end()) {
        open.emplace(key, std::make_pair(e, edge));
        continue;
      }
      const Index e2 = it->second.first;
      const int edge2 = it->second.second;
      const auto ln2 = edge_local_nodes(edge2);
      const bool reversed = elements_[e2].nodes[ln2[0]] != a;
      neighbours_[4 * e + edge] = {e2, edge2, reversed};
      neighbours_[4 * e2 + edge2] = {e, edge, reversed};
      open.erase(it);
    }
  }
}

std::vector<std::pair<Index, int>> SurfaceMesh::boundary_edges() const {
  std::vector<std::pair<Index, int>> out;
  for (Index e = 0; e < n_elements(); ++e)
    for (int edge = 0; edge < 4; ++edge)
      if (!is_degenerate_edge(elements_[e], edge) && neighbours_.size() == 4 * elements_.size() &&
          neighbours_[4 * e + edge].element < 0)
        out.emplace_back(e, edge);
  return out;
}

std::vector<bool> SurfaceMesh::used_dofs() const {
  std::vector<bool> used(n_dofs(), false);
  for (Index e = 0; e < n_elements(); ++e) {
    const ElementMap map = element_map(e);
    for (int k = 0; k < kElementParams; ++k)
      for (int t = 0; t < map.n_terms[k]; ++t)
        if (map.terms[k][t].coef != 0.0) used[map.terms[k][t].dof] = true;
  }
  return used;
}

int SurfaceMesh::compute_arc_length_scale_factors(int max_iterations, double tol) {
  const quadrature::Rule1D gauss = quadrature::gauss_legendre(4);
  int iter = 0;
  for (; iter < max_iterations; ++iter) {
    // Lengths of unique lines, keyed by (direction, sorted node pair).
    std::map<std::tuple<int, Index, Index>, double> line_length;
    for (Index e = 0; e < n_elements(); ++e) {
      const Element& el = elements_[e];
      const auto u = element_parameters(e, geometry_);
      for (int edge = 0; edge < 4; ++edge) {
        if (is_degenerate_edge(el, edge)) continue;
        const int dir = (edge == 0 || edge == 2) ? 0 : 1;
        const auto ln = edge_local_nodes(edge);
        const auto key = std::make_tuple(dir, std::min(el.nodes[ln[0]], el.nodes[ln[1]]),
                                         std::max(el.nodes[ln[0]], el.nodes[ln[1]]));
        if (line_length.count(key)) continue;
        double len = 0.0;
        for (std::size_t g = 0; g < gauss.points.size(); ++g) {
          const auto b = basis::BicubicHermite::evaluate(edge_point(edge, gauss.points[g]), basis::kFirst);
          const Vec3 t = (b.first.col(dir).transpose() * u).transpose();
          len += gauss.weights[g] * t.norm();
        }
        line_length[key] = len;
      }
    }
    // Mean per (node, direction).
    std::vector<double> sum(2 * n_nodes_, 0.0);
    std::vector<int> count(2 * n_nodes_, 0);
    for (const auto& [key, len] : line_length) {
      const int dir = std::get<0>(key);
      for (Index node : {std::get<1>(key), std::get<2>(key)}) {
        sum[2 * node + dir] += len;
        ++count[2 * node + dir];
      }
    }
    double change = 0.0;
    for (Element& el : elements_) {
      for (int n = 0; n < 4; ++n) {
        for (int dir = 0; dir < 2; ++dir) {
          const Index node = el.nodes[n];
          if (count[2 * node + dir] == 0) continue;  // apex xi1 direction
          const double s_new = sum[2 * node + dir] / count[2 * node + dir];
          double& s = el.scale[n][dir];
          change = std::max(change, std::abs(s_new - s) / (1.0 + std::abs(s)));
          s = s_new;
        }
      }
    }
    if (change < tol) return iter + 1;
  }
  return iter;
}

namespace {
void check_frame(const Vec3& a1, const Vec3& a2) {
  if (std::abs(a1.norm() - 1.0) > 1e-9 || std::abs(a2.norm() - 1.0) > 1e-9 || std::abs(a1.dot(a2)) > 1e-9)
    throw std::invalid_argument("mesh generator: axes must be orthonormal");
}
std::vector<double> breaks_or_uniform(const std::vector<double>& b, double len, int n) {
  if (!b.empty()) {
    if (static_cast<int>(b.size()) != n + 1)
      throw std::invalid_argument("make_rectangle_mesh: breakpoints must have n+1 values");
    for (int i = 0; i < n; ++i)
      if (!(b[i + 1] > b[i])) throw std::invalid_argument("make_rectangle_mesh: breakpoints must ascend");
    // Nodal scale factors are the mean of the adjacent widths; beyond a width ratio
    // of about 7 the narrow element's cubic folds back (dx/dxi < 0; measured).
    for (int i = 0; i + 1 < n; ++i) {
      const double w0 = b[i + 1] - b[i], w1 = b[i + 2] - b[i + 1];
      if (std::max(w0, w1) > 7.0 * std::min(w0, w1))
        throw std::invalid_argument(
            "make_rectangle_mesh: adjacent element widths differ by more than 7x "
            "(the arc-length parameterisation would fold); grade more gently");
    }
    return b;
  }
  std::vector<double> out(n + 1);
  for (int i = 0; i <= n; ++i) out[i] = len * i / n;
  return out;
}
}  // namespace

SurfaceMesh make_rectangle_mesh(const Vec3& origin, const Vec3& a1, const Vec3& a2, double length1, double length2,
                                int n1, int n2, const std::vector<double>& breaks1,
                                const std::vector<double>& breaks2) {
  check_frame(a1, a2);
  if (n1 < 1 || n2 < 1 || !(length1 > 0) || !(length2 > 0))
    throw std::invalid_argument("make_rectangle_mesh: need positive sizes and at least one element");
  const auto s = breaks_or_uniform(breaks1, length1, n1);
  const auto t = breaks_or_uniform(breaks2, length2, n2);
  SurfaceMesh mesh;
  Index next = mesh.add_nodes(static_cast<Index>(n1 + 1) * (n2 + 1));
  for (int j = 0; j <= n2; ++j)
    for (int i = 0; i <= n1; ++i) {
      const Index node = next++;
      mesh.geometry().row(SurfaceMesh::dof(node, kValue)) = (origin + s[i] * a1 + t[j] * a2).transpose();
      mesh.geometry().row(SurfaceMesh::dof(node, kD1)) = a1.transpose();
      mesh.geometry().row(SurfaceMesh::dof(node, kD2)) = a2.transpose();
    }
  auto id = [&](int i, int j) { return static_cast<Index>(j) * (n1 + 1) + i; };
  for (int j = 0; j < n2; ++j)
    for (int i = 0; i < n1; ++i) {
      Element el;
      el.nodes = {id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)};
      mesh.add_element(el);
    }
  mesh.build_topology();
  mesh.compute_arc_length_scale_factors();
  return mesh;
}

SurfaceMesh make_disk_mesh(const Vec3& centre, const Vec3& a1, const Vec3& a2, double radius, int n_rings,
                           int n_sectors) {
  check_frame(a1, a2);
  if (n_rings < 1 || n_sectors < 3 || !(radius > 0))
    throw std::invalid_argument("make_disk_mesh: need radius > 0, n_rings >= 1, n_sectors >= 3");
  const double pi = kPi;
  const double dtheta = 2.0 * pi / n_sectors;
  const double dr = radius / n_rings;
  SurfaceMesh mesh;
  const Index apex = mesh.add_nodes(1 + static_cast<Index>(n_rings) * n_sectors);
  Index next = apex + 1;
  mesh.geometry().row(SurfaceMesh::dof(apex, kValue)) = centre.transpose();
  mesh.geometry().row(SurfaceMesh::dof(apex, kD1)) = a1.transpose();
  mesh.geometry().row(SurfaceMesh::dof(apex, kD2)) = a2.transpose();
  // Ring i (1..n_rings), sector node j (0..n_sectors-1).
  auto id = [&](int i, int j) { return 1 + static_cast<Index>(i - 1) * n_sectors + (j % n_sectors); };
  for (int i = 1; i <= n_rings; ++i)
    for (int j = 0; j < n_sectors; ++j) {
      const double th = j * dtheta, r = i * dr;
      const Vec3 radial = std::cos(th) * a1 + std::sin(th) * a2;
      const Vec3 tangent = -std::sin(th) * a1 + std::cos(th) * a2;
      const Index node = next++;
      mesh.geometry().row(SurfaceMesh::dof(node, kValue)) = (centre + r * radial).transpose();
      mesh.geometry().row(SurfaceMesh::dof(node, kD1)) = tangent.transpose();
      mesh.geometry().row(SurfaceMesh::dof(node, kD2)) = radial.transpose();
      // d2x/ds1ds2 with s1 = r theta, s2 = r: d/dr (tangent) = 0 along a ray but the
      // ring arc length grows with r, so x,12 = dtheta*dr*tangent = S1 S2 * (tangent / r).
      mesh.geometry().row(SurfaceMesh::dof(node, kD12)) = (tangent / r).transpose();
      (void)node;
    }
  for (int j = 0; j < n_sectors; ++j) {
    Element el;
    el.shape = ElementShape::kCollapsed;
    el.nodes = {apex, apex, id(1, j), id(1, j + 1)};
    el.apex_angle = {j * dtheta, (j + 1) * dtheta};
    el.scale = {{{dr, dr}, {dr, dr}, {dr * dtheta, dr}, {dr * dtheta, dr}}};
    mesh.add_element(el);
  }
  for (int i = 1; i < n_rings; ++i)
    for (int j = 0; j < n_sectors; ++j) {
      Element el;
      el.nodes = {id(i, j), id(i, j + 1), id(i + 1, j), id(i + 1, j + 1)};
      el.scale = {
          {{i * dr * dtheta, dr}, {i * dr * dtheta, dr}, {(i + 1) * dr * dtheta, dr}, {(i + 1) * dr * dtheta, dr}}};
      mesh.add_element(el);
    }
  mesh.build_topology();
  mesh.compute_arc_length_scale_factors();
  return mesh;
}

}  // namespace sf::mesh

namespace sf::mesh {
SurfaceMesh extract_elements(const SurfaceMesh& mesh, const std::vector<bool>& keep,
                             std::vector<Index>* element_map_out) {
  std::vector<Index> node_map(mesh.n_nodes(), -1);
  std::vector<Index> element_map(mesh.n_elements(), -1);
  Index n_used = 0;
  for (Index e = 0; e < mesh.n_elements(); ++e)
    if (keep[e])
      for (Index n : mesh.element(e).nodes)
        if (node_map[n] == -1) node_map[n] = -2 - n_used++;  // mark; numbered below in order
  for (Index& v : node_map)
    if (v <= -2) v = -2 - v;
  SurfaceMesh out;
  out.add_nodes(n_used);
  for (Index n = 0; n < mesh.n_nodes(); ++n)
    if (node_map[n] >= 0)
      out.geometry().middleRows(SurfaceMesh::dof(node_map[n], 0), kParamsPerNode) =
          mesh.geometry().middleRows(SurfaceMesh::dof(n, 0), kParamsPerNode);
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    if (!keep[e]) continue;
    Element el = mesh.element(e);
    for (Index& n : el.nodes) n = node_map[n];
    element_map[e] = out.add_element(el);
  }
  out.build_topology();
  if (element_map_out) *element_map_out = std::move(element_map);
  return out;
}
}  // namespace sf::mesh

namespace sf::mesh {
SurfaceMesh mesh_from_corners(const Points3& nodes, const std::vector<std::array<Index, 4>>& elements,
                              const std::string& where) {
  const Index nn = nodes.rows();
  SurfaceMesh mesh;
  mesh.add_nodes(nn);
  for (Index n = 0; n < nn; ++n) mesh.geometry().row(SurfaceMesh::dof(n, kValue)) = nodes.row(n);
  // Edge vectors through each node, per xi direction (sign: increasing xi).
  std::vector<Vec3> d1(nn, Vec3::Zero()), d2(nn, Vec3::Zero()), normal(nn, Vec3::Zero());
  std::vector<bool> apex(nn, false);
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const auto& el = elements[e];
    for (Index n : el)
      if (n < 0 || n >= nn)
        throw InputError(where + ": element " + std::to_string(e) + " refers to node " + std::to_string(n) +
                         ", but there are " + std::to_string(nn) + " nodes (ids from 0)");
    const bool collapsed = el[0] == el[1];
    if (el[2] == el[3] || el[0] == el[2] || el[1] == el[3] || el[0] == el[3] || el[1] == el[2])
      throw InputError(where + ": element " + std::to_string(e) +
                       " repeats a node; only n0 == n1 (a collapsed element with its apex there) is allowed");
    auto p = [&](int k) { return Vec3(nodes.row(el[k]).transpose()); };
    const Vec3 nrm = (p(3) - p(0)).cross(p(2) - p(1));
    if (collapsed) apex[el[0]] = true;
    for (int k = 0; k < 4; ++k) normal[el[k]] += nrm;
    if (!collapsed) {
      d1[el[0]] += p(1) - p(0);
      d1[el[1]] += p(1) - p(0);
    }
    d1[el[2]] += p(3) - p(2);
    d1[el[3]] += p(3) - p(2);
    d2[el[0]] += p(2) - p(0);
    d2[el[2]] += p(2) - p(0);
    d2[el[1]] += p(3) - p(1);
    d2[el[3]] += p(3) - p(1);
  }
  for (Index n = 0; n < nn; ++n) {
    if (apex[n]) {
      // Orthonormal tangent frame of the apex from the mean normal.
      const Vec3 nz = normal[n].normalized();
      Vec3 t = Vec3::UnitX() - Vec3::UnitX().dot(nz) * nz;
      if (t.norm() < 0.3) t = Vec3::UnitY() - Vec3::UnitY().dot(nz) * nz;
      t.normalize();
      mesh.geometry().row(SurfaceMesh::dof(n, kD1)) = t.transpose();
      mesh.geometry().row(SurfaceMesh::dof(n, kD2)) = nz.cross(t).transpose();
      continue;
    }
    if (d1[n].norm() > 0) mesh.geometry().row(SurfaceMesh::dof(n, kD1)) = d1[n].normalized().transpose();
    if (d2[n].norm() > 0) mesh.geometry().row(SurfaceMesh::dof(n, kD2)) = d2[n].normalized().transpose();
  }
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const auto& ids = elements[e];
    Element el;
    el.nodes = ids;
    // Initial scale factors: edge lengths (refined below).
    auto p = [&](int k) { return Vec3(nodes.row(ids[k]).transpose()); };
    const double l01 = (p(1) - p(0)).norm(), l23 = (p(3) - p(2)).norm();
    const double l02 = (p(2) - p(0)).norm(), l13 = (p(3) - p(1)).norm();
    el.scale = {{{l01 > 0 ? l01 : l23, l02}, {l01 > 0 ? l01 : l23, l13}, {l23, l02}, {l23, l13}}};
    if (ids[0] == ids[1]) {
      el.shape = ElementShape::kCollapsed;
      const Index a = ids[0];
      const Vec3 t1 = mesh.geometry().row(SurfaceMesh::dof(a, kD1)).transpose();
      const Vec3 t2 = mesh.geometry().row(SurfaceMesh::dof(a, kD2)).transpose();
      const Vec3 r0 = p(2) - p(0), r1 = p(3) - p(0);
      double th0 = std::atan2(r0.dot(t2), r0.dot(t1)), th1 = std::atan2(r1.dot(t2), r1.dot(t1));
      // Going from edge 0-2 to edge 1-3 by the short way round.
      const double pi = kPi;
      while (th1 - th0 > pi) th1 -= 2 * pi;
      while (th1 - th0 < -pi) th1 += 2 * pi;
      el.apex_angle = {th0, th1};
    }
    mesh.add_element(el);
  }
  mesh.build_topology();
  // Directions must agree across shared edges (structured orientation).
  for (Index e = 0; e < mesh.n_elements(); ++e)
    for (int edge = 0; edge < 4; ++edge) {
      const EdgeNeighbour& nb = mesh.neighbour(e, edge);
      if (nb.element < 0) continue;
      const bool same_axis = ((edge % 2) == (nb.edge % 2));
      if (!same_axis || nb.reversed || (edge == nb.edge))
        throw InputError(where + ": elements " + std::to_string(e) + " and " + std::to_string(nb.element) +
                         " meet with disagreeing xi directions; list every element's nodes in the same "
                         "orientation (xi1 from n0 to n1 and n2 to n3, xi2 from n0 to n2)");
    }
  mesh.compute_arc_length_scale_factors();
  return mesh;
}
}  // namespace sf::mesh
