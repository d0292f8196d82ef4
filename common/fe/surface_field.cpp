#include "common/fe/surface_field.hpp"

#include <algorithm>

#include "common/core/error.hpp"

namespace sf::fe {

SurfaceField::SurfaceField(const mesh::SurfaceMesh& mesh, const Eigen::Ref<const MatX>& parameters)
    : mesh_(&mesh), n_components_(static_cast<int>(parameters.cols())) {
  SF_ASSERT(parameters.rows() == mesh.n_dofs(), "parameters must have n_dofs rows");
  cache_.resize(mesh.n_elements());
  for (Index e = 0; e < mesh.n_elements(); ++e) cache_[e] = mesh.element_parameters(e, parameters);
}

FieldPoint SurfaceField::evaluate(Index e, const Vec2& xi, unsigned updates) const {
  const auto b = basis::BicubicHermite::evaluate(xi, updates);
  const MatX& u = cache_[e];
  FieldPoint p;
  p.updated = updates;
  if (updates & basis::kValues) p.value = u.transpose() * b.value;
  if (updates & basis::kFirst) p.first = u.transpose() * b.first;
  if (updates & basis::kSecond) p.second = u.transpose() * b.second;
  return p;
}

SurfacePoint SurfaceField::evaluate3(Index e, const basis::BicubicValues& b) const {
  SF_ASSERT(n_components_ == 3, "evaluate3 needs a 3-component field");
  const MatX& u = cache_[e];
  SurfacePoint p;
  p.updated = b.updated;
  if (b.updated & basis::kValues) p.x.noalias() = u.transpose() * b.value;
  if (b.updated & basis::kFirst) p.dx.noalias() = u.transpose() * b.first;
  if (b.updated & basis::kSecond) p.d2x.noalias() = u.transpose() * b.second;
  return p;
}

SurfacePoint SurfaceField::evaluate3(Index e, const Vec2& xi, unsigned updates) const {
  return evaluate3(e, basis::BicubicHermite::evaluate(xi, updates));
}

namespace {
double pick(const basis::BicubicValues& b, int k, int which) {
  switch (which) {
    case 0:
      return b.value[k];
    case 1:
      return b.first(k, 0);
    case 2:
      return b.first(k, 1);
    case 3:
      return b.second(k, 0);
    case 4:
      return b.second(k, 1);
    default:
      return b.second(k, 2);
  }
}
}  // namespace

GlobalBasisRow global_basis_row(const mesh::ElementMap& map, const basis::BicubicValues& b, int which) {
  GlobalBasisRow row;
  row.dofs.reserve(20);
  row.coefs.reserve(20);
  for (int k = 0; k < mesh::kElementParams; ++k) {
    const double n = pick(b, k, which);
    for (int t = 0; t < map.n_terms[k]; ++t) {
      const Index d = map.terms[k][t].dof;
      const double c = n * map.terms[k][t].coef;
      auto it = std::find(row.dofs.begin(), row.dofs.end(), d);
      if (it == row.dofs.end()) {
        row.dofs.push_back(d);
        row.coefs.push_back(c);
      } else {
        row.coefs[it - row.dofs.begin()] += c;
      }
    }
  }
  return row;
}

ElementDofMap element_dof_map(const mesh::ElementMap& map) {
  ElementDofMap out;
  for (int k = 0; k < mesh::kElementParams; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t)
      if (std::find(out.dofs.begin(), out.dofs.end(), map.terms[k][t].dof) == out.dofs.end())
        out.dofs.push_back(map.terms[k][t].dof);
  out.t = Eigen::MatrixXd::Zero(mesh::kElementParams, static_cast<Index>(out.dofs.size()));
  for (int k = 0; k < mesh::kElementParams; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t) {
      const auto j = std::find(out.dofs.begin(), out.dofs.end(), map.terms[k][t].dof) - out.dofs.begin();
      out.t(k, j) += map.terms[k][t].coef;
    }
  return out;
}

}  // namespace sf::fe
