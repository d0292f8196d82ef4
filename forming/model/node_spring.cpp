#include "forming/model/node_spring.hpp"

#include <cmath>
#include <sstream>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

Index value_dof(const Model& model, BodyNode n, const char* which) {
  if (n.body < 0 || n.body >= model.n_bodies() || n.node < 0 || n.node >= model.ply(n.body).n_nodes()) {
    std::ostringstream os;
    os << "node spring: node " << which << " (body " << n.body << ", node " << n.node << ") is not in the model";
    throw InputError(os.str());
  }
  return model.dof(n.body, n.node, 0, 0);
}

}  // namespace

NodeSpring::NodeSpring(const Model& model, BodyNode a, BodyNode b, double stiffness, double rest_length)
    : a_(value_dof(model, a, "a")), b_(value_dof(model, b, "b")), k_(stiffness), l0_(rest_length) {
  if (!(std::isfinite(k_) && k_ >= 0.0)) {
    std::ostringstream os;
    os << "node spring stiffness: expected a finite value >= 0 (N/mm), found " << k_;
    throw InputError(os.str());
  }
  if (!(std::isfinite(l0_) && l0_ >= 0.0)) {
    std::ostringstream os;
    os << "node spring rest length: expected a finite value >= 0 (mm), found " << l0_;
    throw InputError(os.str());
  }
}

double NodeSpring::length(const Eigen::Ref<const VecX>& x) const {
  return (x.segment<3>(b_) - x.segment<3>(a_)).norm();
}

double NodeSpring::tension(const Eigen::Ref<const VecX>& x) const { return k_ * (length(x) - l0_); }

void NodeSpring::add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& /*context*/,
                        InteractionSums& sums) const {
  const Vec3 d = x.segment<3>(b_) - x.segment<3>(a_);
  const double l = d.norm();
  if (!(l > 0.0)) {
    sums.ok = false;
    sums.message = "node spring between dofs " + std::to_string(a_) + " and " + std::to_string(b_) +
                   " has zero length (direction undefined)";
    return;
  }
  const Vec3 n = d / l;
  const double stretch = l - l0_;
  sums.energy += 0.5 * k_ * stretch * stretch;
  const Vec3 f = k_ * stretch * n;
  sums.force.segment<3>(b_) += f;
  sums.force.segment<3>(a_) -= f;
  if (!sums.stiffness) return;
  const Mat3 nn = n * n.transpose();
  const Mat3 kb = k_ * (nn + (1.0 - l0_ / l) * (Mat3::Identity() - nn));
  MatX block(6, 6);
  block << kb, -kb, -kb, kb;
  const std::vector<Index> dofs = {a_, a_ + 1, a_ + 2, b_, b_ + 1, b_ + 2};
  sums.stiffness->add_block(dofs, dofs, block);
}

}  // namespace sf::forming
