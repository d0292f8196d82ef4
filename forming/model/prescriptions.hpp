#pragma once
// Prescribed unknowns: boundary conditions turned into fixed dofs once, in Model
// numbering, for every solver (static targets at a load factor, dynamic positions in
// time).
//
// Edge conditions of a rectangular ply (forming/model/ply_grid.hpp; docs/forming.md,
// "Edges and dofs"). Each acts on both node layers of the side's surface nodes; the
// derivative "along" the edge is d/ds2 on x0/x1 and d/ds1 on y0/y1, "across" the other:
//   clamp         every parameter (value, d/ds1, d/ds2, d2/ds1ds2) of every coordinate
//                 held at its reference value;
//   displacement  for each given component c: the value moved by displacement_c times
//                 the ramp, and the derivative along the edge of c held (the edge stays
//                 straight in c); the derivative across the edge stays free;
//   symmetry      about the side plane with normal axis k: position k and the along-edge
//                 derivative of k held; the across-edge derivative and the cross
//                 derivative of the other two coordinates held at zero (the mirror
//                 conditions of a C1 field). kBottom: every parameter of coordinate z of
//                 the bottom layer held (the mid-plane of a plate modelled as its upper
//                 half).
// A parameter prescribed by two conditions must get the same value from both (the same
// displacement, and the same ramp unless it is zero); otherwise the pair is a conflict.
//
// Values: positions in mm; derivative parameters are arc-length derivatives
// (dimensionless), held at their reference values.
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "forming/model/model.hpp"
#include "forming/model/ply_grid.hpp"
#include "forming/model/ramp.hpp"

namespace sf::forming {

// A prescribed dof (Model numbering) and its value: a position (mm) or, for a derivative
// parameter, the arc-length derivative. What the static and arc-length solvers take.
struct PrescribedDof {
  Index dof = -1;
  double value = 0.0;
};

// A dof prescribed as a function of time (s -> mm): what the dynamic solver takes.
struct TimedDof {
  Index dof = -1;
  std::function<double(double)> position;
};

struct EdgeCondition {
  enum class Kind { kClamp, kDisplacement, kSymmetry };
  Kind kind = Kind::kClamp;
  PlySide side = PlySide::kX0;
  std::array<std::optional<double>, 3> displacement{};  // kDisplacement: mm per component; empty = free
  Ramp ramp = Ramp::kLinear;                            // kDisplacement
};
// "clamp", "displacement", "symmetry" (the case-file names).
std::string to_string(EdgeCondition::Kind kind);

// One prescribed parameter of a ply: ply node (PlyMesh numbering), parameter d (0 value,
// 1 d/ds1, 2 d/ds2, 3 cross), coordinate; target reference + displacement ramp(lambda).
struct PrescribedParameter {
  Index node = 0;
  int d = 0;
  int coord = 0;
  double displacement = 0.0;  // mm for d = 0, 0 for derivative parameters
  Ramp ramp = Ramp::kLinear;
  int condition = -1;  // index of the condition that prescribed it (the first one)
};

// Two conditions (indices, earlier < later) prescribing some parameter differently.
struct ConditionConflict {
  int earlier = -1;
  int later = -1;
};

struct PlyConditions {
  std::vector<PrescribedParameter> parameters;  // sorted by (node, d, coord), no duplicates
  std::vector<ConditionConflict> conflicts;     // each pair once, in the order found
};

// The parameters the conditions of one ply prescribe, by the rules above.
PlyConditions discretise_conditions(const PlyGrid& grid, const std::vector<EdgeCondition>& conditions);

// A prescribed unknown of the model: x_dof(lambda) = reference + displacement ramp(lambda).
struct Prescription {
  Index dof = -1;
  double reference = 0.0;
  double displacement = 0.0;
  Ramp ramp = Ramp::kLinear;
};

class Prescriptions {
 public:
  void add(const Prescription& p) { list_.push_back(p); }
  // The parameters of body `body` of `model` (reference values from the ply).
  void add(const Model& model, int body, const std::vector<PrescribedParameter>& parameters);

  const std::vector<Prescription>& list() const { return list_; }
  bool empty() const { return list_.empty(); }
  std::size_t size() const { return list_.size(); }

  // Targets at load factor lambda: reference + displacement ramp(lambda).
  std::vector<PrescribedDof> at(double lambda) const;
  // Positions in time for a dynamic run, with the load factor t / end_time (s).
  std::vector<TimedDof> in_time(double end_time) const;

 private:
  std::vector<Prescription> list_;
};

}  // namespace sf::forming
