#pragma once
// A ply as a mesh of "brick" elements: bicubic Hermite in the ply plane (xi1, xi2)
// x linear Lagrange through the thickness (xi3), built on a common/mesh SurfaceMesh.
//
// Nodes and parameters
//   The surface mesh gives n_s surface nodes. The ply has two node layers:
//   layer 0 = bottom face (xi3 = 0), layer 1 = top face (xi3 = 1), so
//       ply node  n = s + layer * n_s                       (s = surface node)
//   Every ply node carries, per coordinate, the four arc-length parameters of the
//   surface mesh (d = 0 value, 1 d/ds1, 2 d/ds2, 3 d2/ds1ds2):
//       parameter p = 4 n + d                               (n_params = 8 n_s)
//   and every parameter has three coordinates (x, y, z):
//       dof = 3 p + i = 3 (4 (s + layer n_s) + d) + i        (n_dofs = 24 n_s)
//   Position fields are stored either as n_params x 3 matrices (row p = parameter
//   p, columns x, y, z, the layout of SurfaceMesh::geometry()) or flattened
//   row-major into n_dofs vectors (dof order above); flatten()/unflatten() convert.
//
//                 top layer (xi3 = 1):   s + n_s
//                     6 -------- 7            brick local node  n = a + 2b + 4c
//                    /|         /|            (a, b, c in {0,1}; xi1, xi2, xi3)
//                   4 -------- 5 |            c = 0: surface node of local surface
//                   | 2 -------|-3                   node a + 2b, bottom layer
//     xi3  xi2      |/         |/             c = 1: same surface node, top layer
//      | /          0 -------- 1
//      |/__ xi1      bottom layer (xi3 = 0):  s
//
// Element map
//   Brick e sits on surface element e. Its 32 xi-parameters (basis order of
//   common/basis/hermite.hpp, k = 4 n + d) are the surface element map of local
//   surface node n % 4 (scale factors S1, S2 of that element node; collapsed apex
//   elements included) applied to the parameters of layer c = n / 4. Both layers
//   use the same scale factors: for a flat ply they are the in-plane arc lengths
//   of either face.
//
// Reference geometry
//   From a FLAT surface (e.g. make_rectangle_mesh) and a thickness h: the surface is
//   the bottom face (PlyPlacement::kBottom) or the mid-surface (kMiddle); the faces
//   are offset by the unit normal N = (d/ds1 x d/ds2)/|.| (the same at every node of
//   a flat surface), and the derivative parameters of both layers are those of the
//   surface. A curved reference ply needs its offset faces' derivatives; pass both
//   layers explicitly (second constructor).
//
// Fibre direction (one per ply, reference configuration, unit):
//   a0 = cos(theta) t1 + sin(theta) t2, theta = layup angle in degrees, t1 = the
//   global x axis projected onto the ply plane (global y when x is normal to the
//   ply), t2 = N x t1. For a ply in the x-y plane with N = +z this is
//   fibre_from_layup_angle(theta) = (cos theta, sin theta, 0).
//
// Units: lengths in mm (any consistent set).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace sf::forming {

inline constexpr int kBrickFunctions = 32;  // BicubicHermiteLinear
inline constexpr int kBrickDofs = 3 * kBrickFunctions;

enum class PlyPlacement { kBottom, kMiddle };

// Linear map from the ply's global parameters to one brick's 32 xi-parameters:
// element parameter k = sum_t terms[k][t].coef * U[terms[k][t].dof], t < n_terms[k],
// where dof here is a PARAMETER index p (multiply by 3 and add the coordinate).
struct BrickMap {
  std::array<std::array<mesh::DofTerm, 2>, kBrickFunctions> terms{};
  std::array<std::uint8_t, kBrickFunctions> n_terms{};
};

class PlyMesh {
 public:
  // Flat surface, thickness > 0 (mm), layup angle (degrees). Throws sf::InputError when
  // the thickness or angle is not positive/finite, or the surface is not flat
  // (relative tolerance 1e-9 of its size).
  PlyMesh(mesh::SurfaceMesh surface, double thickness, double layup_angle_deg,
          PlyPlacement placement = PlyPlacement::kBottom);
  // Explicit reference geometry of both layers, each surface.n_dofs() x 3 (arc-length
  // parameters, bottom = xi3 = 0); surface().geometry() becomes `bottom` (the surface's
  // scale factors are kept). `thickness` is recorded (outputs), not used for the
  // geometry; the ply plane for the layup angle is the normal at surface node 0.
  PlyMesh(mesh::SurfaceMesh surface, const MatX& bottom, const MatX& top, double thickness, double layup_angle_deg);

  // Topology and scale factors; its geometry is the surface the ply was built from
  // (bottom or mid-surface), reference() holds both layers.
  const mesh::SurfaceMesh& surface() const { return surface_; }
  double thickness() const { return thickness_; }
  double layup_angle() const { return layup_angle_deg_; }
  // Unit fibre direction in the reference configuration (see header).
  const Vec3& fibre_direction() const { return fibre_; }

  Index n_surface_nodes() const { return surface_.n_nodes(); }
  Index n_nodes() const { return 2 * surface_.n_nodes(); }
  Index n_elements() const { return surface_.n_elements(); }
  Index n_params() const { return 4 * n_nodes(); }
  Index n_dofs() const { return 3 * n_params(); }

  // Ply node of surface node s in layer 0 (bottom) or 1 (top).
  Index node(Index surface_node, int layer) const { return surface_node + layer * n_surface_nodes(); }
  static Index param(Index node, int d) { return 4 * node + d; }
  static Index dof(Index node, int d, int coord) { return 3 * param(node, d) + coord; }

  BrickMap element_map(Index e) const;
  // xi-parameters (32 x 3) of brick e for a position field (n_params x 3).
  Eigen::Matrix<double, kBrickFunctions, 3> element_parameters(Index e, const Eigen::Ref<const MatX>& field) const;

  // Reference geometry X: n_params x 3, mm.
  const MatX& reference() const { return reference_; }
  // Flattened reference geometry (n_dofs, dof order of the header).
  VecX reference_dofs() const { return flatten(reference_); }

  // Surface nodes on free edges of the surface mesh (ascending, no duplicates).
  std::vector<Index> boundary_surface_nodes() const;

  // n_params x 3 <-> n_dofs (row-major).
  static VecX flatten(const Eigen::Ref<const MatX>& field);
  static MatX unflatten(const Eigen::Ref<const VecX>& dofs);

 private:
  void set_fibre(const Vec3& normal);

  mesh::SurfaceMesh surface_;
  double thickness_ = 0.0;
  double layup_angle_deg_ = 0.0;
  Vec3 fibre_ = Vec3::UnitX();
  MatX reference_;
};

}  // namespace sf::forming
