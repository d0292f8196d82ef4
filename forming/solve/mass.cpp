#include "forming/solve/mass.hpp"

#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <string>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "forming/solve/messages.hpp"

namespace sf::forming {

linalg::SparseMatrix mass_matrix(const Model& model, const std::vector<double>& density) {
  if (static_cast<int>(density.size()) != model.n_bodies())
    throw InputError("mass matrix density: expected one value per body (" + std::to_string(model.n_bodies()) +
                     "), found " + std::to_string(density.size()));
  for (int b = 0; b < model.n_bodies(); ++b)
    if (!(std::isfinite(density[b]) && density[b] >= 0.0)) {
      std::ostringstream os;
      os << "mass matrix density of body " << b << ": expected a finite value >= 0 (t/mm^3), found " << density[b];
      throw InputError(os.str());
    }
  const quadrature::TensorRule<3> rule = model.rule().brick();
  std::vector<basis::BrickValues> values;
  values.reserve(rule.size());
  for (int q = 0; q < rule.size(); ++q)
    values.push_back(basis::BicubicHermiteLinear::evaluate(rule.points[q], basis::kValues | basis::kFirst));

  const Index n = model.n_dofs();
  linalg::TripletAssembler triplets(n, n);
  Index n_el = 0;
  for (int b = 0; b < model.n_bodies(); ++b) n_el += model.ply(b).n_elements();
  triplets.reserve(n_el * 3 * kBrickFunctions * kBrickFunctions);
  std::vector<Index> dofs;
  std::vector<double> coefs;
  std::vector<int> local;
  MatX block;
  for (int b = 0; b < model.n_bodies(); ++b) {
    const PlyMesh& ply = model.ply(b);
    const double rho = density[b];
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickParams X_e = ply.element_parameters(e, ply.reference());
      Eigen::Matrix<double, kBrickFunctions, kBrickFunctions> m_e =
          Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>::Zero();
      for (int q = 0; q < rule.size(); ++q) {
        const Mat3 G = X_e.transpose() * values[q].first;  // G(i, a) = dX_i / dxi_a
        const double det_g = G.determinant();
        if (!(det_g > 0.0))
          throw InputError("mass matrix: body " + std::to_string(b) + " element " + std::to_string(e) +
                           " has an inverted reference geometry (det G " + detail::short_number(det_g) +
                           " at a Gauss point)");
        m_e.noalias() += (rho * rule.weights[q] * det_g) * (values[q].value * values[q].value.transpose());
      }
      const BrickMap map = ply.element_map(e);
      for (int i = 0; i < 3; ++i) {
        dofs.clear();
        coefs.clear();
        local.clear();
        for (int k = 0; k < kBrickFunctions; ++k)
          for (int t = 0; t < map.n_terms[k]; ++t) {
            dofs.push_back(model.offset(b) + 3 * map.terms[k][t].dof + i);
            coefs.push_back(map.terms[k][t].coef);
            local.push_back(k);
          }
        const int m = static_cast<int>(dofs.size());
        block.resize(m, m);
        for (int c = 0; c < m; ++c)
          for (int a = 0; a < m; ++a) block(a, c) = coefs[a] * coefs[c] * m_e(local[a], local[c]);
        triplets.add_block(dofs, dofs, block);
      }
    }
  }
  return triplets.compress();
}

double kinetic_energy(const linalg::SparseMatrix& mass, const Eigen::Ref<const VecX>& velocity) {
  const VecX mv = mass * velocity;
  return 0.5 * velocity.dot(mv);
}

}  // namespace sf::forming
