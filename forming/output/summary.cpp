#include "forming/output/summary.hpp"

#include "forming/material/transversely_isotropic.hpp"

namespace sf::forming {
namespace {

nlohmann::json loads_json(const FormingCase& spec) {
  nlohmann::json lj = nlohmann::json::array();
  for (const CaseLoad& l : spec.loads) {
    nlohmann::json e;
    switch (l.kind) {
      case CaseLoad::Kind::kPressure:
        e = {{"pressure_MPa", l.value}, {"ply", l.ply}, {"face", l.top ? "top" : "bottom"}, {"follower", l.follower}};
        break;
      case CaseLoad::Kind::kGravity:
        e = {{"gravity_mm_s2", {l.vector.x(), l.vector.y(), l.vector.z()}}};
        break;
      case CaseLoad::Kind::kEdgeForce:
        e = {{"edge_force_N", {l.vector.x(), l.vector.y(), l.vector.z()}}, {"ply", l.ply}, {"edge", to_string(l.side)}};
        break;
      case CaseLoad::Kind::kPointForce:
        e = {{"point_force_N", {l.vector.x(), l.vector.y(), l.vector.z()}},
             {"ply", l.ply},
             {"node", {l.node_i, l.node_j}}};
        break;
    }
    if (l.table.empty()) {
      e["ramp"] = to_string(l.ramp);
    } else {
      nlohmann::json t = nlohmann::json::array();
      for (const auto& [time, p] : l.table) t.push_back({time, p});
      e["table_s_MPa"] = t;
    }
    lj.push_back(e);
  }
  return lj;
}

nlohmann::json vec_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json parameters_json(const FormingCase& spec, const Model& model) {
  nlohmann::json j;
  j["units"] = spec.units;
  for (const CaseMaterial& m : spec.materials) {
    nlohmann::json mj{{"name", m.name}, {"given_as", m.given_as}};
    if (m.kind == CaseMaterial::Kind::kNeoHookean) {
      mj["law"] = "neo_hookean";
      mj["mu"] = m.neo_hookean.mu;
      mj["lambda"] = m.neo_hookean.lambda;
    } else if (m.kind == CaseMaterial::Kind::kMooneyRivlin) {
      const MooneyRivlinParams& q = m.mooney_rivlin;
      mj["law"] = "mooney_rivlin (compressible)";
      mj["c10"] = q.c10;
      mj["c01"] = q.c01;
      mj["lambda"] = q.lambda;
      mj["small_strain"] = {{"E", q.young_modulus()}, {"nu", q.poisson_ratio()}, {"mu", q.shear_modulus()}};
    } else {
      const TransverselyIsotropicModuli mod = small_strain_moduli(m.ti);
      mj["law"] = "transversely_isotropic (compressible)";
      mj["mu_T"] = m.ti.mu_T;
      mj["mu_L"] = m.ti.mu_L;
      mj["kappa_f"] = m.ti.kappa_f;
      mj["lambda"] = m.ti.lambda;
      mj["small_strain"] = {{"E_L", mod.E_L}, {"E_T", mod.E_T},     {"G_L", mod.G_L},
                            {"G_T", mod.G_T}, {"nu_LT", mod.nu_LT}, {"nu_TT", mod.nu_TT}};
    }
    j["materials"].push_back(mj);
  }
  for (std::size_t b = 0; b < spec.plies.size(); ++b) {
    const CasePly& p = spec.plies[b];
    const Vec3 a0 = model.ply(static_cast<int>(b)).fibre_direction();
    j["plies"].push_back({{"name", p.name},
                          {"origin", {p.origin.x(), p.origin.y(), p.origin.z()}},
                          {"size", {p.length_x, p.length_y}},
                          {"thickness", p.thickness},
                          {"elements", {p.n1, p.n2}},
                          {"angle", p.angle_deg},
                          {"fibre_direction", {a0.x(), a0.y(), a0.z()}},
                          {"material", p.material}});
    if (p.plane_strain) j["plies"].back()["plane_strain"] = true;
  }
  for (const CaseBoundary& bc : spec.boundaries) {
    nlohmann::json bj{{"kind", to_string(bc.kind)}, {"ply", bc.ply}, {"side", to_string(bc.side)}};
    if (bc.kind == CaseBoundary::Kind::kDisplacement) {
      for (const auto& v : bc.value) bj["value"].push_back(v ? nlohmann::json(*v) : nlohmann::json());
      bj["ramp"] = to_string(bc.ramp);
    }
    j["boundary_conditions"].push_back(bj);
  }
  j["solver"] = {{"steps", spec.solver.steps},
                 {"max_iterations", spec.solver.max_iterations},
                 {"tolerance", spec.solver.tolerance},
                 {"line_search", spec.solver.line_search},
                 {"min_increment", spec.solver.min_increment}};
  if (spec.solver.stabilise_fraction > 0.0 || spec.solver.stabilise_damping > 0.0)
    j["solver"]["stabilise"] = {{"fraction", spec.solver.stabilise_fraction},
                                {"damping", spec.solver.stabilise_damping},
                                {"warn_ratio", spec.solver.stabilise_warn_ratio}};
  if (spec.solver.branch_switch_amplitude > 0.0)
    j["solver"]["branch_switch"] = {{"amplitude", spec.solver.branch_switch_amplitude},
                                    {"give_up_after", spec.solver.branch_switch_give_up_after},
                                    {"retries", spec.solver.branch_switch_retries},
                                    {"last_retry_damping", spec.solver.branch_switch_last_retry_damping}};
  j["output"] = {{"every", spec.output.every},
                 {"samples", {spec.output.samples_inplane, spec.output.samples_thickness}}};
  j["model"] = {{"dofs", model.n_dofs()},
                {"element", "ply brick: bicubic Hermite in-plane x linear through the thickness"},
                {"quadrature", {model.rule().n_inplane, model.rule().n_inplane, model.rule().n_thickness}}};
  return j;
}

nlohmann::json summary_json(const FormingCase& spec, const Model& model, const RunSummary& run) {
  const bool dynamic = spec.solver.dynamic;
  nlohmann::json j;
  j["tool"] = "simform run";
  j["version"] = SF_VERSION;
  j["command_line"] = run.command_line;
  j["inputs"] = {{"case", spec.file}};
  j["parameters"] = parameters_json(spec, model);
  // spec.contacts holds every pair, the laminates' and the diaphragms' included.
  bool with_tools = false, between_plies = false;
  for (const CaseContact& c : spec.contacts) (c.tool >= 0 ? with_tools : between_plies) = true;
  const std::string contact = with_tools && between_plies ? "contact between plies and with tools"
                              : with_tools                ? "contact with tools"
                              : between_plies             ? "contact between plies"
                                                          : "no contact";
  j["analysis"] = dynamic              ? "dynamic (" + spec.solver.integrator + ", " + contact + ")"
                  : run.follower_loads ? "quasi-static, follower loads (" + contact + ")"
                                       : "quasi-static (" + contact + ")";
  if (dynamic) j["time"] = {{"end_time_s", spec.solver.end_time}, {"time_s", run.load_factor * spec.solver.end_time}};
  j["multiplier_updates"] = run.multiplier_updates;
  j["status"] = run.status;
  j["message"] = run.message;
  j["restart"] = {
      {"file", "restart.json"}, {"restarted", run.restarted}, {"from_load_factor", run.restart_load_factor}};
  j["steps"] = {{"requested", spec.solver.steps}, {"converged", run.steps_converged}, {"written", run.frames.size()}};
  j["load_factor"] = run.load_factor;
  j["final_residual"] = run.final_residual;
  j["newton_iterations"] = run.newton_iterations;
  j["tool_edge"] = {
      {"edge", run.tool_label}, {"displacement", vec_json(run.tool_displacement)}, {"force", vec_json(run.tool_force)}};
  j["max_displacement"] = vec_json(run.max_displacement);
  j["loads"] = loads_json(spec);
  j["timings_s"] = {{"build", run.seconds_build},
                    {"solve", run.seconds_solve},
                    {"write", run.seconds_write},
                    {"total", run.seconds_total}};
  nlohmann::json outputs = {"result.pvd", "history.csv", "summary.json", "tool_force.csv", "profiles.csv"};
  for (const auto& f : run.frames) outputs.push_back(f.second);
  j["outputs"] = outputs;
  j["grid_out"] = run.grid_out.empty() ? nlohmann::json() : nlohmann::json(run.grid_out);
  if (run.stabilised)
    j["stabilisation"] = {{"fraction", spec.solver.stabilise_fraction},
                          {"damping", run.stabilisation_damping},
                          {"energy", run.stabilisation_energy},
                          {"ratio", run.stabilisation_ratio},
                          {"max_ratio", run.stabilisation_max_ratio},
                          {"warn_ratio", spec.solver.stabilise_warn_ratio},
                          {"quasi_static", run.stabilisation_max_ratio <= spec.solver.stabilise_warn_ratio}};
  if (spec.solver.branch_switch_amplitude > 0.0) j["branch_switches"] = run.branch_switches;
  j["units"] = {{"length", "mm"}, {"force", "N"}, {"stress", "MPa"}, {"energy", "N mm"}, {"note", spec.units}};
  return j;
}

}  // namespace sf::forming
