#pragma once
// Surface meshes of bicubic Hermite elements (C1 across elements).
//
// Nodes carry, per field component, four parameters by ARC LENGTH:
//   d = 0 value, 1 d/ds1, 2 d/ds2, 3 d2/ds1ds2        (global dof = 4*node + d)
// An element's 16 xi-parameters (basis order of common/basis/hermite.hpp) are a
// linear map of the global parameters:
//   u_e[4n + 0] = U[value]             u_e[4n + 1] = S1(n) U[d/ds1]
//   u_e[4n + 2] = S2(n) U[d/ds2]       u_e[4n + 3] = S1(n) S2(n) U[d2/ds1ds2]
// with per element-node scale factors S1, S2 (arc lengths). Nodal-consistent
// scale factors (the same S at a node for every element, per direction) make the
// fields C1 across elements of different sizes; compute_arc_length_scale_factors()
// sets them from the geometry.
//
// Collapsed (3-noded) elements: local nodes 0 and 1 are one APEX node, the edge
// xi2 = 0 degenerates to a point. The apex node's d/ds1, d/ds2 are two tangent
// vectors D1, D2 of the apex (its cross parameter is unused). With theta_k the
// angle of the radial edge leaving the apex at local node k (k = 0, 1) and
// phi = theta_1 - theta_0:
//   u_e[4k + 0] = U[apex value]
//   u_e[4k + 1] = 0                                    (x,1 = 0 along the apex edge)
//   u_e[4k + 2] = S2(k) (cos theta_k D1 + sin theta_k D2)
//   u_e[4k + 3] = S2(k) phi (-sin theta_k D1 + cos theta_k D2)
// so every radial tangent at the apex lies in span(D1, D2): tangent-plane
// continuity at the pole. The surface Jacobian vanishes at the apex itself.
//
// Element edges (local numbering):   edge 0: xi2 = 0 (nodes 0-1), edge 1: xi1 = 1 (1-3),
//                                    edge 2: xi2 = 1 (2-3),        edge 3: xi1 = 0 (0-2).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/core/error.hpp"
#include "common/core/types.hpp"

namespace sf::mesh {

inline constexpr int kParamsPerNode = 4;
inline constexpr int kValue = 0, kD1 = 1, kD2 = 2, kD12 = 3;
inline constexpr int kElementParams = 16;

enum class ElementShape : std::uint8_t {
  kQuad,       // four distinct nodes
  kCollapsed,  // local nodes 0 and 1 are the same apex node (edge 0 degenerate)
};

struct Element {
  std::array<Index, 4> nodes{{-1, -1, -1, -1}};
  ElementShape shape = ElementShape::kQuad;
  // scale[n] = {S1, S2} at local node n (the cross parameter uses S1*S2).
  std::array<std::array<double, 2>, 4> scale{{{1, 1}, {1, 1}, {1, 1}, {1, 1}}};
  // Collapsed only: angles (radians) of the radial edges at local nodes 0 and 1,
  // measured in the apex frame (D1, D2).
  std::array<double, 2> apex_angle{{0.0, 0.0}};
};

// One term of the element parameter map: element parameter += coef * U[dof].
struct DofTerm {
  Index dof = -1;
  double coef = 0.0;
};

// Linear map from global parameters to one element's 16 xi-parameters.
struct ElementMap {
  std::array<std::array<DofTerm, 2>, kElementParams> terms{};
  std::array<std::uint8_t, kElementParams> n_terms{};
};

// Across an element edge: the neighbour, its edge, and whether the edge runs backwards.
struct EdgeNeighbour {
  Index element = -1;  // -1 = free (boundary) edge
  int edge = -1;
  bool reversed = false;
};

class SurfaceMesh {
 public:
  SurfaceMesh() = default;

  Index add_node();
  // Adds `count` nodes at once (one resize; add_node() in a loop is quadratic). Returns the first id.
  Index add_nodes(Index count);
  Index add_element(const Element& element);

  Index n_nodes() const { return n_nodes_; }
  Index n_elements() const { return static_cast<Index>(elements_.size()); }
  Index n_dofs() const { return kParamsPerNode * n_nodes_; }
  static Index dof(Index node, int d) { return kParamsPerNode * node + d; }

  const Element& element(Index e) const { return elements_[e]; }
  Element& element(Index e) { return elements_[e]; }
  const std::vector<Element>& elements() const { return elements_; }

  // Geometry parameters: n_dofs x 3 (x, y, z), arc-length nodal parameters.
  const MatX& geometry() const { return geometry_; }
  MatX& geometry() { return geometry_; }
  // Node position (value parameter of the geometry).
  Vec3 node_position(Index node) const { return geometry_.row(dof(node, kValue)).transpose(); }

  // The element's parameter map (depends on scale factors and shape).
  ElementMap element_map(Index e) const;
  // u_e (16 x n_components) of any field stored like geometry() (n_dofs x n_components).
  Eigen::Matrix<double, kElementParams, Eigen::Dynamic> element_parameters(Index e,
                                                                           const Eigen::Ref<const MatX>& field) const;

  // Topology: call after adding elements (the generators do).
  void build_topology();
  bool has_topology() const { return neighbours_.size() == 4 * elements_.size(); }
  const EdgeNeighbour& neighbour(Index e, int edge) const {
    SF_ASSERT(has_topology(), "SurfaceMesh::neighbour: call build_topology() first");
    return neighbours_[4 * e + edge];
  }
  // Free edges: (element, local edge), degenerate apex edges excluded.
  std::vector<std::pair<Index, int>> boundary_edges() const;
  static bool is_degenerate_edge(const Element& el, int edge) {
    return el.shape == ElementShape::kCollapsed && edge == 0;
  }
  // Dofs referenced by no element (e.g. an apex cross parameter); fitting pins them.
  std::vector<bool> used_dofs() const;

  // Sets nodal scale factors from arc lengths: each element line's length is the
  // 4-point Gauss integral of |dx/dxi| along it; the factor at a node, per
  // direction, is the mean of the lengths of the lines of that direction meeting
  // there. Iterates (the curve depends on its own factors) until the relative
  // change is below tol or max_iterations. Returns the iterations used.
  int compute_arc_length_scale_factors(int max_iterations = 20, double tol = 1e-10);

 private:
  Index n_nodes_ = 0;
  std::vector<Element> elements_;
  MatX geometry_ = MatX(0, 3);
  std::vector<EdgeNeighbour> neighbours_;
};

// Local node pair (in direction of increasing xi) of a local edge.
std::array<int, 2> edge_local_nodes(int edge);
// Point of the unit cell on local edge `edge` at edge parameter t in [0,1].
Vec2 edge_point(int edge, double t);

// Structured mesh of a flat rectangle: origin + s*a1 + t*a2 with s in [0, L1],
// t in [0, L2] (a1, a2 orthonormal), n1 x n2 elements; optional graded breakpoints
// s1 (n1+1 ascending values from 0 to L1) and s2; adjacent widths may differ by at
// most 7x (std::invalid_argument otherwise). Arc-length parameters exact.
SurfaceMesh make_rectangle_mesh(const Vec3& origin, const Vec3& a1, const Vec3& a2, double length1, double length2,
                                int n1, int n2, const std::vector<double>& breaks1 = {},
                                const std::vector<double>& breaks2 = {});

// Structured mesh of a flat disk (centre, radius, in the plane of orthonormal a1, a2):
// n_rings rings of n_sectors elements; the innermost ring is collapsed elements
// with the apex at the centre. xi1 runs around (anticlockwise about a1 x a2), xi2 outwards.
SurfaceMesh make_disk_mesh(const Vec3& centre, const Vec3& a1, const Vec3& a2, double radius, int n_rings,
                           int n_sectors);

}  // namespace sf::mesh

namespace sf::mesh {
// The sub-mesh of the elements with keep[e] true (nodes renumbered, unused nodes
// dropped, geometry and scale factors kept). `element_map_out` (optional) receives
// old element -> new element (-1 when dropped).
SurfaceMesh extract_elements(const SurfaceMesh& mesh, const std::vector<bool>& keep,
                             std::vector<Index>* element_map_out = nullptr);
}  // namespace sf::mesh

namespace sf::mesh {
// A bicubic Hermite mesh through given corner nodes (n_nodes x 3) and elements
// (global node ids in the local order n0 (0,0), n1 (1,0), n2 (0,1), n3 (1,1)).
// An element whose n0 == n1 is a collapsed (3-noded) element with its apex there.
// Nodal d/ds1, d/ds2 are the unit mean of the element edge vectors through the
// node in each xi direction (cross derivatives 0); an apex gets two orthonormal
// tangents of the mean plane of its elements and the radial angles of its edges
// in that frame; scale factors then come from compute_arc_length_scale_factors().
// Element xi directions must agree across shared edges (as in a structured mesh);
// throws sf::InputError naming the element otherwise, or for bad node ids.
SurfaceMesh mesh_from_corners(const Points3& nodes, const std::vector<std::array<Index, 4>>& elements,
                              const std::string& where = "mesh");
}  // namespace sf::mesh
