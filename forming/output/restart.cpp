#include "forming/output/restart.hpp"

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::forming {
namespace {

// What a restart file must match: the model's size and the plies' definitions.
std::string model_fingerprint(const FormingCase& spec, const Model& model) {
  std::ostringstream os;
  os.precision(17);
  os << "dofs " << model.n_dofs();
  for (const CasePly& p : spec.plies)
    os << "; ply " << p.name << " " << p.origin.transpose() << " " << p.length_x << " " << p.length_y << " "
       << p.thickness << " " << p.n1 << "x" << p.n2 << " " << p.angle_deg << " " << p.material;
  return os.str();
}

// What changed between the case values a restart file was written with and `now`
// ("materials.carbon.E_T: 1000 -> 2000"), at most a few, or "" when nothing did.
std::string case_changes(const nlohmann::json& then, const std::vector<std::pair<std::string, std::string>>& now) {
  std::map<std::string, std::string> before, after(now.begin(), now.end());
  for (const auto& e : then) {
    const std::string key = e.at(0).get<std::string>();
    if (!restart_may_change(key)) before[key] = e.at(1).get<std::string>();
  }
  std::vector<std::string> changes;
  for (const auto& [key, value] : before) {
    const auto it = after.find(key);
    if (it == after.end())
      changes.push_back(key + " removed (was " + value + ")");
    else if (it->second != value)
      changes.push_back(key + ": " + value + " -> " + it->second);
  }
  for (const auto& [key, value] : after)
    if (!before.count(key)) changes.push_back(key + " added (" + value + ")");
  std::string out;
  for (std::size_t i = 0; i < changes.size() && i < 5; ++i) out += (i ? "; " : "") + changes[i];
  if (changes.size() > 5) out += "; and " + std::to_string(changes.size() - 5) + " more";
  return out;
}

}  // namespace

void write_restart(const std::string& path, const FormingCase& spec, const Model& model, const RestartState& s) {
  nlohmann::json j;
  j["format"] = "simform-restart-1";
  j["case"] = spec.file;
  j["fingerprint"] = model_fingerprint(spec, model);
  nlohmann::json values = nlohmann::json::array();
  for (const auto& [key, value] : spec.fingerprint) values.push_back({key, value});
  j["case_values"] = values;
  j["step"] = s.step;
  j["load_factor"] = s.load_factor;
  j["positions"] = std::vector<double>(s.positions.data(), s.positions.data() + s.positions.size());
  j["velocities"] = std::vector<double>(s.velocities.data(), s.velocities.data() + s.velocities.size());
  nlohmann::json m = nlohmann::json::array();
  for (int b = 0; b < model.n_bodies(); ++b) m.push_back({{"p", model.pressures(b)}, {"T", model.tensions(b)}});
  j["multipliers"] = m;
  j["history_rows"] = s.history_rows;
  nlohmann::json f = nlohmann::json::array();
  for (const auto& [lam, name] : s.frames) f.push_back({lam, name});
  j["frames"] = f;
  nlohmann::json parts = nlohmann::json::array();
  for (const io::PvdDataSet& p : s.parts) parts.push_back({p.time, p.file, p.part});
  j["parts"] = parts;
  j["stabilisation"] = {{"damping", s.stabilisation_damping}, {"energy", s.stabilisation_energy}};
  j["next_increment"] = s.next_increment;
  if (s.predictor_rate.size() > 0)
    j["predictor_rate"] =
        std::vector<double>(s.predictor_rate.data(), s.predictor_rate.data() + s.predictor_rate.size());
  io::write_file_atomic(path, j.dump());
}

RestartState read_restart(const std::string& path, const FormingCase& spec, Model& model) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": no restart file (a run writes it with every frame; run without --restart first)");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable restart file (" + e.what() + ")");
  }
  if (j.value("format", "") != "simform-restart-1") throw InputError(path + ": not a simform restart file");
  if (j.contains("case_values") && !spec.fingerprint.empty()) {
    std::string changes;
    try {
      changes = case_changes(j.at("case_values"), spec.fingerprint);
    } catch (const std::exception& e) {
      throw InputError(path + ": not a readable restart file (" + e.what() + ")");
    }
    if (!changes.empty())
      throw InputError(path + ": written for a different case; changed since: " + changes +
                       " (a restart may change only the output settings and the solver's max_iterations, "
                       "tolerance, min_increment, line_search, predictor, linear, branch_switch and stabilise "
                       "warn_ratio; run without --restart to start again)");
  }
  if (j.value("fingerprint", "") != model_fingerprint(spec, model))
    throw InputError(path +
                     ": written for a different model (plies, meshes or materials changed since; only solver, "
                     "loads and output settings may change for a restart)");
  RestartState s;
  s.step = j.at("step").get<int>();
  s.load_factor = j.at("load_factor").get<double>();
  const std::vector<double> x = j.at("positions").get<std::vector<double>>();
  s.positions = Eigen::Map<const VecX>(x.data(), static_cast<Index>(x.size()));
  if (j.contains("velocities")) {
    const std::vector<double> v = j.at("velocities").get<std::vector<double>>();
    s.velocities = Eigen::Map<const VecX>(v.data(), static_cast<Index>(v.size()));
  }
  const nlohmann::json& m = j.at("multipliers");
  for (int b = 0; b < model.n_bodies() && b < static_cast<int>(m.size()); ++b)
    if (model.constrained(b))
      model.set_multipliers(b, m[b].at("p").get<std::vector<double>>(), m[b].at("T").get<std::vector<double>>());
  s.history_rows = j.value("history_rows", "");
  try {
    for (const auto& f : j.at("frames")) s.frames.emplace_back(f.at(0).get<double>(), f.at(1).get<std::string>());
    if (j.contains("parts"))
      for (const auto& p : j.at("parts"))
        s.parts.push_back({p.at(0).get<double>(), p.at(1).get<std::string>(), p.at(2).get<int>()});
    if (j.contains("stabilisation")) {
      s.stabilisation_damping = j.at("stabilisation").at("damping").get<double>();
      s.stabilisation_energy = j.at("stabilisation").at("energy").get<double>();
    }
    s.next_increment = j.value("next_increment", 0.0);
    if (j.contains("predictor_rate")) {
      const std::vector<double> v = j.at("predictor_rate").get<std::vector<double>>();
      s.predictor_rate = Eigen::Map<const VecX>(v.data(), static_cast<Index>(v.size()));
    }
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable restart file (" + e.what() + ")");
  }
  if (s.positions.size() != model.n_dofs()) throw InputError(path + ": wrong number of positions");
  if (s.predictor_rate.size() != 0 && s.predictor_rate.size() != model.n_dofs())
    throw InputError(path + ": predictor_rate has " + std::to_string(s.predictor_rate.size()) + " entries, expected " +
                     std::to_string(model.n_dofs()) + " (one a dof)");
  return s;
}

}  // namespace sf::forming
