#pragma once
// history.csv of a run (CONTRACT.md; docs/forming.md "Outputs"): one row per converged
// step, row 0 the reference state, columns
//
//   step, load_factor, tool_ux, tool_uy, tool_uz, tool_fx, tool_fy, tool_fz,
//   strain_energy, newton_iterations, cutbacks, residual
//
// tool_u*: mean displacement of the tool edge's value parameters, both layers (mm);
// tool_f*: the sum of the reactions on them (N); strain_energy: the elements' stored
// energy (N mm); residual: |r_f| at the end of the step (N).
//
// The tool edge is the edge of the first `displacement` condition of the case (or of the
// first condition when there is none). Each rigid tool (forming/model/interaction.hpp
// ToolReaction) adds its own columns after these, in the order of the model's
// interactions:
//
//   time, <tool>_ux, <tool>_uy, <tool>_uz, <tool>_fx, <tool>_fy, <tool>_fz, ...
//
// time (s): the process time (load control) or the time (dynamics); <tool>_u*: the
// tool's displacement (mm); <tool>_f*: the force the plies exert on it (N; a punch
// pressing down on a ply sees f_z > 0). Row 0 is the start state as given, before any
// solve: it reports zero forces (tool edge and tools), since its contact pressures
// (e.g. a sheet laid on a die at gap 0 inside the contact band) are not balanced by
// anything yet and would read as a load the process never applied.
//
// A run with viscous stabilisation (solver stabilise, forming/solve/stabilisation.hpp)
// adds, last,
//
//   stabilisation_energy, stabilisation_ratio
//
// the energy the stabilisation dissipated from the start to the step (N mm) and its
// ratio to the strain energy of the step (dimensionless; 0 where that is 0).
#include <sstream>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/csv.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

struct ToolEdge {
  std::string label;                // e.g. "displacement on x1 of ply 'ply'"; empty: none
  std::vector<Index> value_dofs_x;  // global dof of coordinate 0 of each value parameter
};
ToolEdge tool_edge(const FormingCase& spec, const Model& model);

struct ToolState {
  Vec3 displacement = Vec3::Zero();  // mm
  Vec3 force = Vec3::Zero();         // N
};
// reactions: n_dofs, or empty (zero force).
ToolState measure(const ToolEdge& tool, const VecX& x, const VecX& X, const VecX& reactions);

class HistoryTable {
 public:
  // `stabilised`: the stabilisation columns are added.
  HistoryTable(const Model& model, ToolEdge tool, bool stabilised = false);
  // The rows of an earlier run (restart.json), appended after the header. Throws
  // InputError naming the first row whose number of columns is not this table's (a
  // restart file written for other tools or without stabilisation, or edited by hand).
  void append_rows(const std::string& rows);
  // A row for step k; returns the tool's state in it. `context`: the time and rates of
  // the step (rigid tools' reactions include friction).
  // `stabilisation_energy`: dissipated from the start to this step, N mm (stabilised tables).
  ToolState add_row(int k, double load_factor, const VecX& x, const VecX& reactions, int iterations, int cutbacks,
                    double residual, const InteractionContext& context = {}, double stabilisation_energy = 0.0);
  // Row 0: the start state x, nothing solved: zero forces (see above), the tools where they are.
  void add_start_row(const VecX& x);
  // The strain energy (N mm) of the last row added.
  double last_strain_energy() const { return last_strain_energy_; }
  const ToolEdge& tool() const { return tool_; }
  std::string text() const { return out_.str(); }
  std::string rows() const { return out_.str().substr(header_size_); }

 private:
  const Model& model_;
  ToolEdge tool_;
  VecX X_;
  std::ostringstream out_;
  std::size_t n_columns_ = 0;
  io::CsvWriter writer_;
  std::size_t header_size_ = 0;
  bool tools_ = false;  // some interaction reports tool reactions
  bool stabilised_ = false;
  double last_strain_energy_ = 0.0;
  // Writes one row; `forces`: false writes 0 for every force (the unsolved start row).
  ToolState write_row(int k, double load_factor, const VecX& x, const VecX& reactions, int iterations, int cutbacks,
                      double residual, const InteractionContext& context, double stabilisation_energy, bool forces);
};

}  // namespace sf::forming
