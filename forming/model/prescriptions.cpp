#include "forming/model/prescriptions.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>
#include <utility>

namespace sf::forming {

std::string to_string(EdgeCondition::Kind kind) {
  switch (kind) {
    case EdgeCondition::Kind::kClamp:
      return "clamp";
    case EdgeCondition::Kind::kDisplacement:
      return "displacement";
    case EdgeCondition::Kind::kSymmetry:
      return "symmetry";
  }
  return "?";
}

PlyConditions discretise_conditions(const PlyGrid& grid, const std::vector<EdgeCondition>& conditions) {
  const Index n_s = grid.n_surface_nodes();
  std::map<std::tuple<Index, int, int>, PrescribedParameter> dofs;
  std::set<std::pair<int, int>> reported;  // (earlier, later) condition pairs
  PlyConditions out;
  for (std::size_t b = 0; b < conditions.size(); ++b) {
    const EdgeCondition& bc = conditions[b];
    auto add = [&](Index node, int d, int coord, double u) {
      const PrescribedParameter pr{node, d, coord, u, bc.ramp, static_cast<int>(b)};
      const auto [it, inserted] = dofs.emplace(std::make_tuple(node, d, coord), pr);
      if (inserted) return;
      const PrescribedParameter& old = it->second;
      const bool same = old.displacement == u && (u == 0.0 || old.ramp == bc.ramp);
      if (!same && reported.insert({old.condition, static_cast<int>(b)}).second)
        out.conflicts.push_back({old.condition, static_cast<int>(b)});
    };
    const bool x_side = bc.side == PlySide::kX0 || bc.side == PlySide::kX1;
    const int along = x_side ? 2 : 1;   // derivative along the edge
    const int across = x_side ? 1 : 2;  // derivative across the edge
    for (const Index s : grid.side_surface_nodes(bc.side)) {
      for (int layer = 0; layer < 2; ++layer) {
        const Index node = s + layer * n_s;
        switch (bc.kind) {
          case EdgeCondition::Kind::kClamp:
            for (int d = 0; d < 4; ++d)
              for (int c = 0; c < 3; ++c) add(node, d, c, 0.0);
            break;
          case EdgeCondition::Kind::kDisplacement:
            for (int c = 0; c < 3; ++c) {
              if (!bc.displacement[static_cast<std::size_t>(c)]) continue;
              add(node, 0, c, *bc.displacement[static_cast<std::size_t>(c)]);
              add(node, along, c, 0.0);
            }
            break;
          case EdgeCondition::Kind::kSymmetry:
            if (bc.side == PlySide::kBottom) {
              if (layer == 0)
                for (int d = 0; d < 4; ++d) add(node, d, 2, 0.0);
            } else {
              const int k = x_side ? 0 : 1;  // normal of the plane
              add(node, 0, k, 0.0);
              add(node, along, k, 0.0);
              for (int c = 0; c < 3; ++c)
                if (c != k) {
                  add(node, across, c, 0.0);
                  add(node, 3, c, 0.0);
                }
            }
            break;
        }
      }
    }
  }
  out.parameters.reserve(dofs.size());
  for (const auto& kv : dofs) out.parameters.push_back(kv.second);
  return out;
}

void Prescriptions::add(const Model& model, int body, const std::vector<PrescribedParameter>& parameters) {
  const VecX X = model.ply(body).reference_dofs();
  for (const PrescribedParameter& p : parameters) {
    const Index local = PlyMesh::dof(p.node, p.d, p.coord);
    list_.push_back({model.offset(body) + local, X[local], p.displacement, p.ramp});
  }
}

std::vector<PrescribedDof> Prescriptions::at(double lambda) const {
  std::vector<PrescribedDof> out;
  out.reserve(list_.size());
  for (const Prescription& p : list_) out.push_back({p.dof, p.reference + p.displacement * ramp_value(p.ramp, lambda)});
  return out;
}

std::vector<TimedDof> Prescriptions::in_time(double end_time) const {
  std::vector<TimedDof> out;
  out.reserve(list_.size());
  for (const Prescription& p : list_)
    out.push_back({p.dof, [p, end_time](double t) {
                     return p.reference + p.displacement * ramp_value(p.ramp, std::clamp(t / end_time, 0.0, 1.0));
                   }});
  return out;
}

}  // namespace sf::forming
