#include "forming/model/tied_faces.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/quadrature/gauss.hpp"

namespace sf::forming {
namespace {

using Values = Eigen::Matrix<double, kBrickFunctions, 1>;

Values face_values(double s, double t, bool top) {
  const basis::BrickValues bv = basis::BicubicHermiteLinear::evaluate(Vec3(s, t, top ? 1.0 : 0.0), basis::kValues);
  Values v;
  for (int k = 0; k < kBrickFunctions; ++k) v[k] = bv.value[k];
  return v;
}

}  // namespace

TiedFaces::TiedFaces(std::string label, const Model& model, int slave, bool slave_top, int master, bool master_top,
                     double stiffness, int points)
    : label_(std::move(label)), reference_(model.reference_positions()) {
  if (slave < 0 || slave >= model.n_bodies() || master < 0 || master >= model.n_bodies() || slave == master)
    throw InputError("tie " + label_ + ": expected two different bodies of the model");
  if (!(stiffness > 0.0) || !std::isfinite(stiffness))
    throw InputError("tie " + label_ + ": expected a positive stiffness (N/mm^3)");
  if (points < 1) throw InputError("tie " + label_ + ": expected at least one point per face direction");
  const PlyMesh& ps = model.ply(slave);
  const PlyMesh& pm = model.ply(master);
  const MatX Rs = ps.reference(), Rm = pm.reference();
  // The master elements' plan boxes at the reference (flat rectangles: affine in s, t).
  std::vector<std::array<Vec3, 2>> boxes;
  for (Index e = 0; e < pm.n_elements(); ++e) {
    const auto X = pm.element_parameters(e, Rm);
    boxes.push_back({X.transpose() * face_values(0, 0, master_top), X.transpose() * face_values(1, 1, master_top)});
  }
  const quadrature::Rule1D line = quadrature::gauss_legendre(points);
  // Per pair of elements (slave e, master f): sum_q w N_a N_b of the scalar functions.
  struct Blocks {
    Eigen::Matrix<double, kBrickFunctions, kBrickFunctions> ss, sm, mm;
  };
  std::map<std::pair<Index, Index>, Blocks> pairs;
  for (Index e = 0; e < ps.n_elements(); ++e) {
    const auto X = ps.element_parameters(e, Rs);
    for (std::size_t a = 0; a < line.points.size(); ++a)
      for (std::size_t b = 0; b < line.points.size(); ++b) {
        const double s = line.points[a], t = line.points[b];
        const basis::BrickValues bv =
            basis::BicubicHermiteLinear::evaluate(Vec3(s, t, slave_top ? 1.0 : 0.0), basis::kValues | basis::kFirst);
        const Vec3 xs = X.transpose() * bv.first.col(0), xt = X.transpose() * bv.first.col(1);
        const double w = line.weights[a] * line.weights[b] * xs.cross(xt).norm();
        Values ns;
        for (int k = 0; k < kBrickFunctions; ++k) ns[k] = bv.value[k];
        const Vec3 P = X.transpose() * ns;
        for (Index f = 0; f < pm.n_elements(); ++f) {
          const auto& box = boxes[static_cast<std::size_t>(f)];
          const Vec3 span = box[1] - box[0];
          const double u = (P[0] - box[0][0]) / span[0], v = (P[1] - box[0][1]) / span[1];
          if (!(u >= -1e-12 && u <= 1.0 + 1e-12 && v >= -1e-12 && v <= 1.0 + 1e-12)) continue;
          const Values nm = face_values(std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0), master_top);
          Blocks& bl = pairs
                           .try_emplace({e, f}, Blocks{Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>::Zero(),
                                                       Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>::Zero(),
                                                       Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>::Zero()})
                           .first->second;
          bl.ss += w * ns * ns.transpose();
          bl.sm += w * ns * nm.transpose();
          bl.mm += w * nm * nm.transpose();
          ++paired_;
          break;
        }
      }
  }
  // K = k sum [N_s; -N_m] [N_s; -N_m]^T per coordinate, through the element dof maps.
  linalg::TripletAssembler K(model.n_dofs(), model.n_dofs());
  const auto add = [&](const Model::ElementDofs& r, const Model::ElementDofs& c,
                       const Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>& m, double sign) {
    for (std::size_t i = 0; i < r.dofs.size(); ++i)
      for (std::size_t j = 0; j < c.dofs.size(); ++j) {
        if (r.local[i] % 3 != c.local[j] % 3) continue;  // coordinates do not couple
        K.add(r.dofs[i], c.dofs[j], sign * stiffness * r.coefs[i] * c.coefs[j] * m(r.local[i] / 3, c.local[j] / 3));
      }
  };
  for (const auto& [ef, bl] : pairs) {
    const Model::ElementDofs ds = model.element_dofs(slave, ef.first), dm = model.element_dofs(master, ef.second);
    add(ds, ds, bl.ss, 1.0);
    add(ds, dm, bl.sm, -1.0);
    add(dm, ds, Eigen::Matrix<double, kBrickFunctions, kBrickFunctions>(bl.sm.transpose()), -1.0);
    add(dm, dm, bl.mm, 1.0);
  }
  K_ = K.compress();
}

void TiedFaces::add_to(const Eigen::Ref<const VecX>& x, const InteractionContext&, InteractionSums& sums) const {
  const VecX d = x - reference_;
  const VecX f = K_ * d;
  sums.energy += 0.5 * d.dot(f);
  sums.force += f;
  if (!sums.stiffness) return;
  for (int c = 0; c < K_.outerSize(); ++c)
    for (linalg::SparseMatrix::InnerIterator it(K_, c); it; ++it) sums.stiffness->add(it.row(), it.col(), it.value());
}

}  // namespace sf::forming
