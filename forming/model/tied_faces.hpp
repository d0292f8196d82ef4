#pragma once
// Tied faces, an Interaction (forming/model/interaction.hpp): a face of one ply bonded to
// a face of another by a penalty, e.g. the laminate held between two diaphragms by the
// vacuum as a tie rather than by contact friction (docs/forming.md "Diaphragms",
// `vacuum: {..., hold: tie}`).
//
// Each Gauss point q (n x n per face) of the slave face is paired once, in the reference
// configuration, with the point of the master face at the same plan position (the plies
// are flat rectangles there; a point beyond the master face stays unpaired). With
// g_q = (x_s(q) - x_m(q)) - (X_s(q) - X_m(q)) (mm; zero at the reference, so an initial
// offset between the faces is kept, not closed):
//   energy  E = k/2 sum_q w_q |g_q|^2      (N mm; k N/mm^3, w_q reference area, mm^2)
//   force   f = K (x - X),  K = k sum_q w_q B_q^T B_q   (B_q: g_q = B_q (x - X))
//   tangent K: constant and symmetric, built once.
// The faces can neither open nor slide against each other (to the penalty's compliance
// 1/k mm per MPa of traction). Where the paired points coincide at the reference (faces
// that touch, as a laminate's outer face and a diaphragm's) a rigid motion of both plies
// costs nothing; an initial offset would resist rotations (g is not rotated).
#include <string>

#include "common/linalg/sparse.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

class TiedFaces final : public Interaction {
 public:
  // Slave: face `slave_top` (true: top) of body `slave`; master likewise. k > 0 (N/mm^3),
  // points >= 1 Gauss points per face direction. Throws sf::InputError on a bad body, k or
  // points.
  TiedFaces(std::string label, const Model& model, int slave, bool slave_top, int master, bool master_top,
            double stiffness, int points = 6);

  std::string name() const override { return "tie " + label_; }
  void add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context, InteractionSums& sums) const override;

  int paired_points() const { return paired_; }
  const linalg::SparseMatrix& matrix() const { return K_; }

 private:
  std::string label_;
  VecX reference_;
  linalg::SparseMatrix K_;
  int paired_ = 0;
};

}  // namespace sf::forming
