#include "forming/output/history.hpp"

#include <algorithm>
#include <utility>

#include "common/core/error.hpp"
#include "forming/model/ply_grid.hpp"

namespace sf::forming {

ToolEdge tool_edge(const FormingCase& spec, const Model& model) {
  ToolEdge t;
  const CaseBoundary* chosen = nullptr;
  for (const CaseBoundary& bc : spec.boundaries)
    if (bc.kind == CaseBoundary::Kind::kDisplacement) {
      chosen = &bc;
      break;
    }
  if (!chosen && !spec.boundaries.empty()) chosen = &spec.boundaries.front();
  if (!chosen) return t;
  const CasePly& p = spec.plies[static_cast<std::size_t>(chosen->ply_index)];
  const PlyGrid grid{p.n1, p.n2};
  t.label = to_string(chosen->kind) + " on " + to_string(chosen->side) + " of ply '" + p.name + "'";
  for (const Index s : grid.side_surface_nodes(chosen->side))
    for (int layer = 0; layer < 2; ++layer)
      t.value_dofs_x.push_back(model.dof(chosen->ply_index, s + layer * grid.n_surface_nodes(), 0, 0));
  return t;
}

ToolState measure(const ToolEdge& tool, const VecX& x, const VecX& X, const VecX& reactions) {
  ToolState s;
  if (tool.value_dofs_x.empty()) return s;
  for (const Index d : tool.value_dofs_x)
    for (int c = 0; c < 3; ++c) {
      s.displacement[c] += x[d + c] - X[d + c];
      if (reactions.size() > 0) s.force[c] += reactions[d + c];
    }
  s.displacement /= static_cast<double>(tool.value_dofs_x.size());
  return s;
}

namespace {

std::vector<std::string> history_columns(const Model& model, bool stabilised) {
  std::vector<std::string> cols = {"step",          "load_factor",       "tool_ux",  "tool_uy",
                                   "tool_uz",       "tool_fx",           "tool_fy",  "tool_fz",
                                   "strain_energy", "newton_iterations", "cutbacks", "residual"};
  std::vector<ToolReaction> tools;
  const VecX X = model.reference_positions();
  for (int i = 0; i < model.n_interactions(); ++i)
    for (const ToolReaction& r : model.interaction(i).reactions(X, {})) tools.push_back(r);
  if (!tools.empty()) {
    cols.push_back("time");
    for (const ToolReaction& r : tools)
      for (const char* c : {"_ux", "_uy", "_uz", "_fx", "_fy", "_fz"}) cols.push_back(r.tool + c);
  }
  if (stabilised) {
    cols.push_back("stabilisation_energy");
    cols.push_back("stabilisation_ratio");
  }
  return cols;
}

}  // namespace

HistoryTable::HistoryTable(const Model& model, ToolEdge tool, bool stabilised)
    : model_(model),
      tool_(std::move(tool)),
      X_(model.reference_positions()),
      n_columns_(history_columns(model, stabilised).size()),
      writer_(out_, history_columns(model, stabilised)),
      header_size_(out_.str().size()),
      stabilised_(stabilised) {
  for (int i = 0; i < model.n_interactions(); ++i) tools_ = tools_ || !model.interaction(i).reactions(X_, {}).empty();
}

void HistoryTable::append_rows(const std::string& rows) {
  std::istringstream in(rows);
  std::string line;
  for (int k = 1; std::getline(in, line); ++k) {
    if (line.empty()) continue;
    const std::size_t n = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    if (n != n_columns_)
      throw InputError("its history row " + std::to_string(k) + " has " + std::to_string(n) +
                       " columns where this run's history.csv has " + std::to_string(n_columns_) +
                       " (the file was written for other tools or stabilisation settings, or edited; run "
                       "without --restart to start again)");
  }
  out_ << rows;
}

ToolState HistoryTable::add_row(int k, double load_factor, const VecX& x, const VecX& reactions, int iterations,
                                int cutbacks, double residual, const InteractionContext& context,
                                double stabilisation_energy) {
  return write_row(k, load_factor, x, reactions, iterations, cutbacks, residual, context, stabilisation_energy, true);
}

void HistoryTable::add_start_row(const VecX& x) { write_row(0, 0.0, x, VecX(), 0, 0, 0.0, {}, 0.0, false); }

ToolState HistoryTable::write_row(int k, double load_factor, const VecX& x, const VecX& reactions, int iterations,
                                  int cutbacks, double residual, const InteractionContext& context,
                                  double stabilisation_energy, bool forces) {
  const ToolState ts = measure(tool_, x, X_, forces ? reactions : VecX());
  const Assembly a = model_.assemble(x, context, false);
  last_strain_energy_ = a.strain_energy;
  writer_.begin_row().add(k).add(load_factor);
  for (int c = 0; c < 3; ++c) writer_.add(ts.displacement[c]);
  for (int c = 0; c < 3; ++c) writer_.add(ts.force[c]);
  writer_.add(a.strain_energy).add(iterations).add(cutbacks).add(residual);
  if (tools_) {
    writer_.add(context.time);
    for (int i = 0; i < model_.n_interactions(); ++i)
      for (const ToolReaction& r : model_.interaction(i).reactions(x, context)) {
        for (int c = 0; c < 3; ++c) writer_.add(r.displacement[c]);
        for (int c = 0; c < 3; ++c) writer_.add(forces ? r.force[c] : 0.0);
      }
  }
  if (stabilised_)
    writer_.add(stabilisation_energy).add(a.strain_energy > 0.0 ? stabilisation_energy / a.strain_energy : 0.0);
  writer_.end_row();
  return ts;
}

}  // namespace sf::forming
