#include "forming/model/ply_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

// Flatness of a surface, relative to its size (coordinates of O(size) built in floating point).
constexpr double kFlatRel = 1e-9;

void require(bool ok, const std::string& what, double found) {
  if (ok) return;
  std::ostringstream os;
  os.precision(10);
  os << "ply " << what << ", found " << found;
  throw InputError(os.str());
}

Vec3 node_normal(const MatX& geometry, Index node) {
  const Vec3 d1 = geometry.row(mesh::SurfaceMesh::dof(node, mesh::kD1)).transpose();
  const Vec3 d2 = geometry.row(mesh::SurfaceMesh::dof(node, mesh::kD2)).transpose();
  return d1.cross(d2);
}

// The checks both constructors make of the ply's own numbers.
void check_ply_parameters(double thickness, double layup_angle_deg) {
  require(std::isfinite(thickness) && thickness > 0.0, "thickness: expected a positive length (mm)", thickness);
  require(std::isfinite(layup_angle_deg), "layup angle: expected a finite angle (degrees)", layup_angle_deg);
}

}  // namespace

PlyMesh::PlyMesh(mesh::SurfaceMesh surface, double thickness, double layup_angle_deg, PlyPlacement placement)
    : surface_(std::move(surface)), thickness_(thickness), layup_angle_deg_(layup_angle_deg) {
  check_ply_parameters(thickness, layup_angle_deg);
  require(surface_.n_nodes() > 0 && surface_.n_elements() > 0, "surface: expected at least one element; nodes",
          static_cast<double>(surface_.n_nodes()));
  const MatX& g = surface_.geometry();
  const Vec3 n0 = node_normal(g, 0);
  require(n0.norm() > 0.0, "surface: expected independent tangents d/ds1, d/ds2 at node 0; |d1 x d2|", n0.norm());
  const Vec3 normal = n0.normalized();
  // Flatness: every parameter row other than the values lies in the plane, every
  // value on it.
  const Vec3 x0 = surface_.node_position(0);
  double size = 0.0;
  for (Index s = 0; s < surface_.n_nodes(); ++s) size = std::max(size, (surface_.node_position(s) - x0).norm());
  double worst = 0.0;
  for (Index s = 0; s < surface_.n_nodes(); ++s) {
    worst = std::max(worst, std::abs((surface_.node_position(s) - x0).dot(normal)) / std::max(size, 1e-300));
    for (int d = 1; d < 4; ++d) {
      const Vec3 v = g.row(mesh::SurfaceMesh::dof(s, d)).transpose();
      worst = std::max(worst, std::abs(v.dot(normal)) / std::max(v.norm(), 1.0));
    }
  }
  require(worst <= kFlatRel,
          "surface: expected a flat surface (pass both layers explicitly for a curved ply); "
          "relative out-of-plane deviation",
          worst);
  const double shift_bottom = placement == PlyPlacement::kBottom ? 0.0 : -0.5 * thickness;
  const Index ns = surface_.n_nodes();
  reference_.resize(n_params(), 3);
  for (int layer = 0; layer < 2; ++layer) {
    const double shift = shift_bottom + layer * thickness;
    for (Index s = 0; s < ns; ++s)
      for (int d = 0; d < 4; ++d) {
        Eigen::RowVector3d row = g.row(mesh::SurfaceMesh::dof(s, d));
        if (d == mesh::kValue) row += shift * normal.transpose();
        reference_.row(param(node(s, layer), d)) = row;
      }
  }
  set_fibre(normal);
}

PlyMesh::PlyMesh(mesh::SurfaceMesh surface, const MatX& bottom, const MatX& top, double thickness,
                 double layup_angle_deg)
    : surface_(std::move(surface)), thickness_(thickness), layup_angle_deg_(layup_angle_deg) {
  check_ply_parameters(thickness, layup_angle_deg);
  require(bottom.rows() == surface_.n_dofs() && bottom.cols() == 3,
          "bottom geometry: expected surface.n_dofs() x 3 rows; rows", static_cast<double>(bottom.rows()));
  require(top.rows() == surface_.n_dofs() && top.cols() == 3, "top geometry: expected surface.n_dofs() x 3 rows; rows",
          static_cast<double>(top.rows()));
  reference_.resize(n_params(), 3);
  reference_.topRows(surface_.n_dofs()) = bottom;
  reference_.bottomRows(surface_.n_dofs()) = top;
  surface_.geometry() = bottom;
  const Vec3 n0 = node_normal(bottom, 0);
  require(n0.norm() > 0.0, "bottom geometry: expected independent tangents at node 0; |d1 x d2|", n0.norm());
  set_fibre(n0.normalized());
}

void PlyMesh::set_fibre(const Vec3& normal) {
  Vec3 t1 = Vec3::UnitX() - normal * normal.x();
  if (t1.norm() < 1e-8) t1 = Vec3::UnitY() - normal * normal.y();
  t1.normalize();
  const Vec3 t2 = normal.cross(t1);
  const double t = layup_angle_deg_ * kPi / 180.0;
  fibre_ = (std::cos(t) * t1 + std::sin(t) * t2).normalized();
}

BrickMap PlyMesh::element_map(Index e) const {
  const mesh::ElementMap sm = surface_.element_map(e);
  const Index layer_shift = 4 * n_surface_nodes();  // parameters per layer
  BrickMap map;
  for (int c = 0; c < 2; ++c)
    for (int k = 0; k < mesh::kElementParams; ++k) {
      const int kb = 16 * c + k;  // n = a + 2b + 4c, k_brick = 4n + d = 16c + (4(a+2b) + d)
      map.n_terms[kb] = sm.n_terms[k];
      for (int t = 0; t < sm.n_terms[k]; ++t)
        map.terms[kb][t] = {sm.terms[k][t].dof + c * layer_shift, sm.terms[k][t].coef};
    }
  return map;
}

Eigen::Matrix<double, kBrickFunctions, 3> PlyMesh::element_parameters(Index e,
                                                                      const Eigen::Ref<const MatX>& field) const {
  SF_ASSERT(field.rows() == n_params() && field.cols() == 3, "field must be n_params x 3");
  const BrickMap map = element_map(e);
  Eigen::Matrix<double, kBrickFunctions, 3> u = Eigen::Matrix<double, kBrickFunctions, 3>::Zero();
  for (int k = 0; k < kBrickFunctions; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t) u.row(k) += map.terms[k][t].coef * field.row(map.terms[k][t].dof);
  return u;
}

std::vector<Index> PlyMesh::boundary_surface_nodes() const {
  std::vector<Index> out;
  for (const auto& [e, edge] : surface_.boundary_edges()) {
    const auto ln = mesh::edge_local_nodes(edge);
    out.push_back(surface_.element(e).nodes[ln[0]]);
    out.push_back(surface_.element(e).nodes[ln[1]]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

VecX PlyMesh::flatten(const Eigen::Ref<const MatX>& field) {
  SF_ASSERT(field.cols() == 3, "field must have 3 columns");
  VecX v(3 * field.rows());
  for (Index p = 0; p < field.rows(); ++p) v.segment<3>(3 * p) = field.row(p).transpose();
  return v;
}

MatX PlyMesh::unflatten(const Eigen::Ref<const VecX>& dofs) {
  SF_ASSERT(dofs.size() % 3 == 0, "dof vector length must be a multiple of 3");
  MatX m(dofs.size() / 3, 3);
  for (Index p = 0; p < m.rows(); ++p) m.row(p) = dofs.segment<3>(3 * p).transpose();
  return m;
}

}  // namespace sf::forming
