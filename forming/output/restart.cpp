#include "forming/output/restart.hpp"

#include <fstream>
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

}  // namespace

void write_restart(const std::string& path, const FormingCase& spec, const Model& model, const RestartState& s) {
  nlohmann::json j;
  j["format"] = "simform-restart-1";
  j["case"] = spec.file;
  j["fingerprint"] = model_fingerprint(spec, model);
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
  for (const auto& f : j.at("frames")) s.frames.emplace_back(f.at(0).get<double>(), f.at(1).get<std::string>());
  if (s.positions.size() != model.n_dofs()) throw InputError(path + ": wrong number of positions");
  return s;
}

}  // namespace sf::forming
