#include "forming/stability/input.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "common/core/error.hpp"
#include "forming/case/yaml_reader.hpp"

namespace sf::forming::stability {
namespace {

// What a node holds, for messages: the case reader's one wording.
using case_yaml::describe;

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  std::string at(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    if (m.is_null()) return file_;
    return file_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& message) const {
    throw InputError(at(n) + ": " + message);
  }

  void mapping(const YAML::Node& n, const std::string& what, const std::vector<std::string>& allowed) const {
    if (!n.IsMap()) fail(n, what + ": expected a mapping (key: value), found " + describe(n));
    std::vector<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(it->first, what + ": unknown key '" + key + "' (expected one of: " + list + ")");
      }
      if (std::find(seen.begin(), seen.end(), key) != seen.end())
        fail(it->first, what + ": key '" + key + "' given twice");
      seen.push_back(key);
    }
  }

  double number(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(n, what + ": expected a number, found " + describe(n));
    const std::string& s = n.Scalar();
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
      fail(n, what + ": expected a finite number, found '" + s + "'");
    return v;
  }

  int integer(const YAML::Node& n, const std::string& what, int lo, int hi) const {
    const double v = number(n, what);
    if (v != std::floor(v) || v < lo || v > hi)
      fail(n, what + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " +
                  n.Scalar());
    return static_cast<int>(v);
  }

  std::vector<double> numbers(const YAML::Node& n, const std::string& what, std::size_t count) const {
    if (!n.IsSequence() || n.size() != count)
      fail(n, what + ": expected a list of " + std::to_string(count) + " numbers, found " +
                  (n.IsSequence() ? "a list of " + std::to_string(n.size()) : describe(n)));
    std::vector<double> v;
    for (std::size_t i = 0; i < count; ++i) v.push_back(number(n[i], what));
    return v;
  }

  // Keys of a mapping of numbers, all required unless listed optional.
  std::vector<double> named(const YAML::Node& n, const std::string& what, const std::vector<std::string>& keys,
                            std::vector<bool>* present = nullptr, std::size_t n_required = 0) const {
    mapping(n, what, keys);
    std::vector<double> v(keys.size(), 0.0);
    if (present) present->assign(keys.size(), false);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const YAML::Node k = n[keys[i]];
      if (!k.IsDefined()) {
        if (i < (n_required ? n_required : keys.size())) fail(n, what + ": missing required key '" + keys[i] + "'");
        continue;
      }
      v[i] = number(k, what + "." + keys[i]);
      if (present) (*present)[i] = true;
    }
    return v;
  }

 private:
  std::string file_;
};

}  // namespace

StabilityInput read_stability_input(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(buffer.str());
  } catch (const YAML::Exception& e) {
    throw InputError(located_message(path, e.mark.line + 1, e.mark.column + 1, "invalid YAML: " + e.msg));
  }
  const Reader r(path);
  if (!root.IsDefined() || root.IsNull()) throw InputError(path + ": the file is empty");
  r.mapping(root, "stability input",
            {"units", "fibres", "viscosity", "thickness", "rates", "shear_rate", "tensions", "tractions", "scan"});

  StabilityInput s;
  TrellisSpec& spec = s.spec;
  // A key the file does not give is reported at the top-level mapping, by name (the
  // defaults name the command-line options, which the file's user may not have used).
  s.at = r.at(root);
  const auto absent = [&](const char* key) { return s.at + ": key '" + key + "'"; };
  spec.fibres_at = absent("fibres");
  spec.viscosity_at = absent("viscosity");
  spec.thickness_at = absent("thickness");
  spec.rates_at = absent("rates");
  spec.rate33_at = absent("rates.D33");
  spec.shear_rate_at = absent("shear_rate");
  spec.tensions_at = absent("tensions");
  spec.tractions_at = absent("tractions");
  if (const YAML::Node n = root["units"]; n.IsDefined()) {
    if (!n.IsScalar()) r.fail(n, "units: expected a text note such as \"mm, s, MPa\", found " + describe(n));
    s.units = n.Scalar();
  }
  if (const YAML::Node n = root["fibres"]; n.IsDefined()) {
    const std::vector<double> v = r.numbers(n, "fibres (angles of families a and b, degrees)", 2);
    spec.fibre_angles_deg = {v[0], v[1]};
    spec.fibres_at = r.at(n);
    s.has_fibres = true;
  }
  if (const YAML::Node n = root["viscosity"]; n.IsDefined()) {
    spec.viscosity = r.number(n, "viscosity (MPa s)");
    spec.viscosity_at = r.at(n);
    s.has_viscosity = true;
  }
  if (const YAML::Node n = root["thickness"]; n.IsDefined()) {
    spec.thickness = r.number(n, "thickness (mm)");
    spec.thickness_at = r.at(n);
    s.has_thickness = true;
  }
  if (const YAML::Node n = root["shear_rate"]; n.IsDefined()) {
    spec.shear_rate = r.number(n, "shear_rate (1/s)");
    spec.shear_rate_at = r.at(n);
  }
  if (const YAML::Node n = root["rates"]; n.IsDefined()) {
    std::vector<bool> present;
    const std::vector<double> v = r.named(n, "rates (1/s)", {"D11", "D22", "D12", "D33"}, &present, 3);
    spec.rates = std::array<double, 3>{v[0], v[1], v[2]};
    spec.rates_at = r.at(n);
    if (present[3]) {
      spec.rate33 = v[3];
      spec.rate33_at = r.at(n["D33"]);
    }
  }
  if (const YAML::Node n = root["tensions"]; n.IsDefined()) {
    const std::vector<double> v = r.named(n, "tensions (MPa)", {"T_a", "T_b"});
    spec.tensions = std::array<double, 2>{v[0], v[1]};
    spec.tensions_at = r.at(n);
  }
  if (const YAML::Node n = root["tractions"]; n.IsDefined()) {
    const std::vector<double> v = r.named(n, "tractions (MPa)", {"sigma11", "sigma22", "sigma12"});
    spec.tractions = std::array<double, 3>{v[0], v[1], v[2]};
    spec.tractions_at = r.at(n);
  }
  if (const YAML::Node n = root["scan"]; n.IsDefined()) {
    r.mapping(n, "scan", {"wavelengths", "n_wavelengths", "n_directions"});
    if (const YAML::Node w = n["wavelengths"]; w.IsDefined()) {
      const std::vector<double> v = r.numbers(w, "scan.wavelengths (min, max in mm)", 2);
      if (!(v[0] > 0.0) || !(v[1] > v[0]))
        r.fail(w,
               "scan.wavelengths: expected 0 < min < max (mm), found [" + w[0].Scalar() + ", " + w[1].Scalar() + "]");
      s.scan.min_wavelength = v[0];
      s.scan.max_wavelength = v[1];
    }
    if (const YAML::Node k = n["n_wavelengths"]; k.IsDefined())
      s.scan.n_wavelengths = r.integer(k, "scan.n_wavelengths", 2, 10000);
    if (const YAML::Node k = n["n_directions"]; k.IsDefined())
      s.scan.n_directions = r.integer(k, "scan.n_directions", 4, 36000);
  }
  return s;
}

}  // namespace sf::forming::stability
