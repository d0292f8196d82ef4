#pragma once
// Axial linear spring between two nodes of the model (of one body or of two bodies), an
// Interaction (forming/model/interaction.hpp): a stitch between plies, a compliant
// support, and the first user of the interaction hook.
//
//   l = |x_b - x_a| (current length, mm),  n = (x_b - x_a) / l,
//   energy     E = k/2 (l - l0)^2                                    (N mm)
//   force      f_b = dE/dx_b = k (l - l0) n,   f_a = -f_b            (N, internal-force sign)
//   stiffness  d f_b / d x_b = k [ n n^T + (1 - l0/l) (I - n n^T) ]  (N/mm, symmetric)
//              = -d f_b / d x_a = -d f_a / d x_b = d f_a / d x_a.
// The nodes are value parameters (positions) of ply nodes; the spring acts on their three
// coordinates. A zero current length (direction undefined) is an inadmissible state.
#include <string>

#include "common/core/types.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// A ply node of a body (PlyMesh node numbering: surface node + layer * n_surface_nodes).
struct BodyNode {
  int body = 0;
  Index node = 0;
};

class NodeSpring final : public Interaction {
 public:
  // Spring of stiffness k (N/mm, >= 0) and rest length l0 (mm, >= 0) between the value
  // parameters of nodes a and b of `model`. Throws sf::InputError for a node outside the
  // model or a negative or non-finite k or l0.
  NodeSpring(const Model& model, BodyNode a, BodyNode b, double stiffness, double rest_length);

  std::string name() const override { return "node spring"; }
  void add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context, InteractionSums& sums) const override;

  // Current length l (mm) and tension k (l - l0) (N, positive when stretched) at x.
  double length(const Eigen::Ref<const VecX>& x) const;
  double tension(const Eigen::Ref<const VecX>& x) const;

 private:
  Index a_ = 0, b_ = 0;  // global dof of coordinate 0 of each node's value parameter
  double k_ = 0.0, l0_ = 0.0;
};

}  // namespace sf::forming
